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
Joint acceleration (posture) task.

q_ddot = qdd_ref + P (q_ref - q) + I integral + D (qd_ref - qd).
"""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask
from ..servo.pid_controller import PIDController


class JointAccelerationTask(GenericTask):
    def __init__(self, name: str):
        super().__init__(name)
        self._pid = PIDController(0)
        self._q_ref = np.zeros(0)
        self._qd_ref = np.zeros(0)
        self._qdd_ref = np.zeros(0)
        self._has_desired = False
        self._q_err = np.zeros(0)
        self._qd_err = np.zeros(0)

    def rows(self) -> int:
        return self.layout.ndof

    def set_robot_model(self, robot) -> None:
        super().set_robot_model(robot)
        n = robot.get_nr_of_degrees_of_freedom()
        if self._pid.dimension != n:
            self._pid.resize(n)  # gains are set per joint, so only once the robot is known
        if self._q_ref.size != n:
            self._q_ref, self._qd_ref, self._qdd_ref = np.zeros(n), np.zeros(n), np.zeros(n)
            self._q_err, self._qd_err = np.zeros(n), np.zeros(n)

    def resize(self, layout) -> None:
        super().resize(layout)
        self.E[:, layout.joint_acc] = np.eye(layout.ndof)
        self.diagonal_columns = layout.joint_acc

    def pid(self) -> PIDController:
        return self._pid

    def set_desired(self, q, qd=None, qdd=None) -> None:
        n = self._q_ref.size if self.robot is not None else np.asarray(q).size
        vals = []
        for what, x in (('position', q), ('velocity', qd), ('acceleration', qdd)):
            a = np.zeros(n) if x is None else np.asarray(x, dtype=float).reshape(-1)
            if a.shape != (n,) or not np.all(np.isfinite(a)):
                raise ValueError(
                    f"task '{self.name}': desired joint {what} must be {n} finite values"
                )
            vals.append(a)
        if self.robot is None:
            self._q_ref, self._qd_ref, self._qdd_ref = vals
        else:
            self._q_ref[:], self._qd_ref[:], self._qdd_ref[:] = vals
        self._has_desired = True

    def has_desired(self) -> bool:
        """Tell whether a desired value was set (else the task holds where it first computes)."""
        return self._has_desired

    def get_desired(self):
        return self._q_ref.copy(), self._qd_ref.copy(), self._qdd_ref.copy()

    def hold_current_position(self) -> None:
        self.set_desired(self.robot.get_joint_positions())

    def get_position_error(self) -> np.ndarray:
        return self._q_err.copy()

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        robot = self.robot
        if not self._has_desired:
            self.hold_current_position()
        np.subtract(self._q_ref, robot.buffers.q, out=self._q_err)
        np.subtract(self._qd_ref, robot.buffers.v, out=self._qd_err)
        cmd = self._pid.compute_command(self._q_err, self._qd_err, dt)
        np.add(self._qdd_ref, cmd, out=self.f)
