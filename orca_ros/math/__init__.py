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
"""Maths helpers (rotations, poses, ramps)."""

from .rotations import (
    is_rotation_matrix,
    make_transform,
    orientation_error,
    pose_error,
    quat_from_kuka_convention,
    quat_from_rpy,
    rotation_from_rpy,
    rotation_log,
    rpy_from_rotation,
)
from .smooth_ramp import smooth_ramp, smooth_ramp_derivative

__all__ = [
    'is_rotation_matrix',
    'make_transform',
    'orientation_error',
    'pose_error',
    'quat_from_kuka_convention',
    'quat_from_rpy',
    'rotation_from_rpy',
    'rotation_log',
    'rpy_from_rotation',
    'smooth_ramp',
    'smooth_ramp_derivative',
]
