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
"""Container for a robot's state, sized once for a model (the reference's EigenRobotState)."""

from __future__ import annotations

import numpy as np


class RobotState:
    """
    State of a (fixed or floating base) robot: every array preallocated by :meth:`resize`.

    ``world_H_base`` (4x4), ``joint_pos`` (n), ``base_velocity`` (6: linear, angular in the world
    frame), ``joint_vel`` (n), ``gravity`` (3).
    """

    def __init__(self, ndof: int = 0):
        self.resize(ndof)

    def resize(self, ndof: int) -> None:
        self.ndof = int(ndof)
        self.world_H_base = np.eye(4)
        self.joint_pos = np.zeros(self.ndof)
        self.joint_vel = np.zeros(self.ndof)
        self.base_velocity = np.zeros(6)
        self.gravity = np.array([0.0, 0.0, -9.81])

    def set_zero(self) -> None:
        self.world_H_base[:] = np.eye(4)
        self.joint_pos[:] = 0.0
        self.joint_vel[:] = 0.0
        self.base_velocity[:] = 0.0

    def copy(self) -> 'RobotState':
        s = RobotState(self.ndof)
        s.world_H_base[:] = self.world_H_base
        s.joint_pos[:] = self.joint_pos
        s.joint_vel[:] = self.joint_vel
        s.base_velocity[:] = self.base_velocity
        s.gravity[:] = self.gravity
        return s
