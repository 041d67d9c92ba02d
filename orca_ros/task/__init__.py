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
"""Tasks: weighted least-squares objectives on the reduced QP variables."""

from .cartesian_task import CartesianTask
from .com_task import CoMTask
from .generic_task import GenericTask
from .joint_acceleration_task import JointAccelerationTask
from .joint_torque_task import JointTorqueTask
from .momentum_task import MomentumTask
from .regularisation_task import RegularisationTask
from .wrench_task import WrenchTask

__all__ = [
    'CartesianTask',
    'CoMTask',
    'GenericTask',
    'JointAccelerationTask',
    'JointTorqueTask',
    'MomentumTask',
    'RegularisationTask',
    'WrenchTask',
]
