"""orca_ros: a whole-body reactive robot controller (QP on joint accelerations/torques) with ROS 2 nodes.

``import orca_ros as orca`` gives the whole core API (no ROS import happens here; the ROS 2 nodes live in
``orca_ros.ros`` and are imported only on demand).
"""
import os as _os

# The controller's matrices are tiny: BLAS worker threads only add latency, and their scheduling changes the
# last bits of results from run to run (lockstep simulations stop being bit-identical, measured). One thread
# unless the user decided otherwise; this must happen before numpy is first imported.
_os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
_os.environ.setdefault("OMP_NUM_THREADS", "1")

from .common import ActivationState, TaskBase
from .constraint import (
    BilateralContact,
    Contact,
    SurfaceContact,
    surface_contact,
    DynamicsEquationConstraint,
    GenericConstraint,
    JointAccelerationLimitConstraint,
    JointBoxConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)
from .math import (
    make_transform,
    orientation_error,
    pose_error,
    quat_from_kuka_convention,
    quat_from_rpy,
    rotation_from_rpy,
    smooth_ramp,
)
from .optim import Controller, ProblemLayout, QPSolver, ResolutionStrategy, ReturnCode, WeightedProblem
from .robot import WORLD_FRAME, RobotModel, RobotState
from .servo import CartesianAccelerationPID, PIDController
from .task import CartesianTask, CoMTask, GenericTask, JointAccelerationTask, JointTorqueTask, RegularisationTask, WrenchTask
from .utils import Logger, MinJerkPositionTrajectory, get_logger
from .paths import default_urdf_path, share_path

__version__ = "0.1.0"

__all__ = [
    "BilateralContact", "CoMTask", "Contact", "SurfaceContact", "WrenchTask", "surface_contact",
    "ActivationState", "CartesianAccelerationPID", "CartesianTask", "Controller", "DynamicsEquationConstraint",
    "GenericConstraint", "GenericTask", "JointAccelerationLimitConstraint", "JointAccelerationTask",
    "JointBoxConstraint", "JointPositionLimitConstraint", "JointTorqueLimitConstraint", "JointTorqueTask",
    "JointVelocityLimitConstraint", "Logger", "MinJerkPositionTrajectory", "PIDController", "ProblemLayout",
    "QPSolver", "RegularisationTask", "ResolutionStrategy", "ReturnCode", "RobotModel", "RobotState", "TaskBase",
    "WORLD_FRAME", "WeightedProblem", "default_urdf_path", "get_logger", "make_transform", "orientation_error",
    "pose_error", "quat_from_kuka_convention", "quat_from_rpy", "rotation_from_rpy", "share_path", "smooth_ramp",
]
