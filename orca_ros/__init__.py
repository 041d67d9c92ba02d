# Copyright 2026 orca_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.
"""
orca_ros.

A whole-body reactive robot controller (QP on joint accelerations/torques) with ROS 2 nodes.

``import orca_ros as orca`` gives the whole core API (no ROS import happens here; the ROS 2 nodes
live in ``orca_ros.ros`` and are imported only on demand).
"""

import os as _os

# The controller's matrices are tiny: BLAS worker threads only add latency, and their scheduling
# changes the last bits of results from run to run (lockstep simulations stop being bit-identical,
# measured). One thread unless the user decided otherwise; this must happen before numpy is first
# imported.
_os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
_os.environ.setdefault('OMP_NUM_THREADS', '1')

from .common import ActivationState, TaskBase  # noqa: E402
from .constraint import (  # noqa: E402
    BalanceConstraint,
    BilateralContact,
    CollisionAvoidanceConstraint,
    Contact,
    DynamicsEquationConstraint,
    GenericConstraint,
    JointAccelerationLimitConstraint,
    JointBoxConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
    surface_contact,
    SurfaceContact,
)
from .math import (  # noqa: E402
    make_transform,
    orientation_error,
    pose_error,
    quat_from_kuka_convention,
    quat_from_rpy,
    rotation_from_rpy,
    smooth_ramp,
)
from .optim import (  # noqa: E402
    Controller,
    ProblemLayout,
    QPSolver,
    ResolutionStrategy,
    ReturnCode,
    WeightedProblem,
)
from .paths import default_urdf_path, share_path  # noqa: E402
from .robot import RobotModel, RobotState, WORLD_FRAME  # noqa: E402
from .servo import CartesianAccelerationPID, PIDController  # noqa: E402
from .task import (  # noqa: E402
    CartesianTask,
    CoMTask,
    GenericTask,
    JointAccelerationTask,
    JointTorqueTask,
    MomentumTask,
    RegularisationTask,
    WrenchTask,
)
from .utils import get_logger, Logger, MinJerkPositionTrajectory  # noqa: E402

__version__ = '0.1.0'

__all__ = [
    'BilateralContact',
    'CoMTask',
    'MomentumTask',
    'Contact',
    'BalanceConstraint',
    'CollisionAvoidanceConstraint',
    'SurfaceContact',
    'WrenchTask',
    'surface_contact',
    'ActivationState',
    'CartesianAccelerationPID',
    'CartesianTask',
    'Controller',
    'DynamicsEquationConstraint',
    'GenericConstraint',
    'GenericTask',
    'JointAccelerationLimitConstraint',
    'JointAccelerationTask',
    'JointBoxConstraint',
    'JointPositionLimitConstraint',
    'JointTorqueLimitConstraint',
    'JointTorqueTask',
    'JointVelocityLimitConstraint',
    'Logger',
    'MinJerkPositionTrajectory',
    'PIDController',
    'ProblemLayout',
    'QPSolver',
    'RegularisationTask',
    'ResolutionStrategy',
    'ReturnCode',
    'RobotModel',
    'RobotState',
    'TaskBase',
    'WORLD_FRAME',
    'WeightedProblem',
    'default_urdf_path',
    'get_logger',
    'make_transform',
    'orientation_error',
    'pose_error',
    'quat_from_kuka_convention',
    'quat_from_rpy',
    'rotation_from_rpy',
    'share_path',
    'smooth_ramp',
]
