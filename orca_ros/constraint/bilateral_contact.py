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
Bilateral contact.

A frame rigidly held by the environment, or two links of the robot held together.

The contact owns a full wrench w (6 QP variables, world axes, at the frame's origin), unbounded (a
grip or a weld pulls as well as pushes). Held by the environment (``other_frame`` None): the frame
does not accelerate, J nu_dot + J_dot nu = 0 (6 rows), and w enters the dynamics through J^T.
Between two links a and b (their frames coinciding while held): the relative acceleration is zero,
(J_a - J_b) nu_dot + (bias_a - bias_b) = 0, and the internal wrench acts on a and its opposite on
b, i.e. through (J_a - J_b)^T. Switched off, w = 0.
"""

from __future__ import annotations

import numpy as np

from .contact import ContactBase, ContactExistenceCondition


class BilateralContact(ContactBase):
    def __init__(self, name: str, frame: str | None = None, other_frame: str | None = None):
        super().__init__(name)
        self.other_frame = other_frame
        self._other_fid = None
        self.existence = ContactExistenceCondition(f'{name}_existence', self)
        self.wrench_lower[:] = -np.inf
        self.wrench_upper[:] = np.inf
        if frame is not None:
            self.set_contact_frame(frame)

    def set_robot_model(self, robot) -> None:
        super().set_robot_model(robot)
        if self.other_frame is not None:
            self._other_fid = robot.get_frame_id(self.other_frame)

    def rows(self) -> int:
        return 0  # no inequality: only the existence condition and the free wrench

    def relative_terms(self):
        _, J, _, bias = self.robot.world_frame_terms(self.fid)
        if self._other_fid is None:
            return J, bias
        _, Jb, _, bias_b = self.robot.world_frame_terms(self._other_fid)
        return J - Jb, bias - bias_b

    existence_rows = 6

    def existence_terms(self):
        return self.relative_terms()

    def fill_wrench_jacobian(self, out: np.ndarray) -> None:
        out[:] = self.relative_terms()[0]

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        pass
