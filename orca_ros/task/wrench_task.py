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
Wrench task.

The external wrench of a contact follows a desired wrench, with a PI servo on the measured one.

    w = w_des + Kp (w_des - w_meas) + Ki integral(w_des - w_meas)

(world axes, [force, torque] at the contact point). Without a measurement (``set_current_wrench``
never called) the task asks for w_des itself. E selects the contact's wrench variables in the QP.
"""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask
from ..servo.pid_controller import PIDController


class WrenchTask(GenericTask):
    def __init__(self, name: str, contact=None):
        super().__init__(name)
        self.contact = contact
        self._pid = PIDController(6)
        self._pid.set_proportional_gain(0.0)
        self._w_des = np.zeros(6)
        self._w_meas = None

    def set_contact(self, contact) -> None:
        self.contact = contact

    def rows(self) -> int:
        return 6

    def pid(self) -> PIDController:
        return self._pid

    def set_desired(self, wrench) -> None:
        w = np.asarray(wrench, dtype=float).reshape(-1)
        if w.shape != (6,) or not np.all(np.isfinite(w)):
            raise ValueError(
                f"task '{self.name}': desired wrench must be 6 finite values [force, torque]"
            )
        self._w_des = w

    def get_desired(self) -> np.ndarray:
        return self._w_des.copy()

    def set_current_wrench(self, wrench) -> None:
        w = np.asarray(wrench, dtype=float).reshape(-1)
        if w.shape != (6,) or not np.all(np.isfinite(w)):
            raise ValueError(f"task '{self.name}': measured wrench must be 6 finite values")
        self._w_meas = w

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        if self.contact is None or self.contact.wrench_index is None:
            raise RuntimeError(
                f"wrench task '{self.name}': its contact is not part of the controller"
            )
        self.E.fill(0.0)
        ws = self.contact.wrench_slice()
        self.E[:, ws] = np.eye(6)
        target = self._w_des
        if self._w_meas is not None:
            target = target + self._pid.compute_command(
                self._w_des - self._w_meas, np.zeros(6), dt
            )
        self.f[:] = target
