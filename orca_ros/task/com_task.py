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
Centre-of-mass task: J_com nu_dot + J_dot_com nu = a_des, with a PD(+I) servo in world axes.

    a_des = a_ref + Kp (p_ref - p_com) + Kd (v_ref - v_com) [+ Ki integral].

Not in the reference library; what balancing a legged robot needs (the CoM over the support
polygon). Without a target the task holds the CoM where it is when it first computes.
"""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask
from ..servo.pid_controller import PIDController


class CoMTask(GenericTask):
    def __init__(self, name: str):
        super().__init__(name)
        self._pid = PIDController(3)
        self._pid.set_proportional_gain(100.0)
        self._pid.set_derivative_gain(20.0)
        self._p_ref = np.zeros(3)
        self._has_desired = False  # none yet: the task holds the CoM where it first computes
        self._v_ref = np.zeros(3)
        self._a_ref = np.zeros(3)
        self._err = np.zeros(3)

    def rows(self) -> int:
        return 3

    def pid(self) -> PIDController:
        return self._pid

    def set_desired(self, position, velocity=None, acceleration=None) -> None:
        vals = []
        for what, x in (
            ('position', position),
            ('velocity', velocity),
            ('acceleration', acceleration),
        ):
            a = np.zeros(3) if x is None else np.asarray(x, dtype=float).reshape(-1)
            if a.shape != (3,) or not np.all(np.isfinite(a)):
                raise ValueError(f"task '{self.name}': desired CoM {what} must be 3 finite values")
            vals.append(a)
        # in place: the compiled cycle reads these arrays
        self._p_ref[:], self._v_ref[:], self._a_ref[:] = vals
        self._has_desired = True

    def has_desired(self) -> bool:
        """Tell whether a desired value was set (else the task holds where it first computes)."""
        return self._has_desired

    def get_desired(self):
        return (
            (self._p_ref.copy() if self._has_desired else None),
            self._v_ref.copy(),
            self._a_ref.copy(),
        )

    def get_current_position(self) -> np.ndarray:
        return self.robot.get_center_of_mass()

    def get_position_error(self) -> np.ndarray:
        return self._err.copy()

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        p, J, v, bias = self.robot.get_center_of_mass_terms()
        if not self._has_desired:
            self.set_desired(p)
        np.subtract(self._p_ref, p, out=self._err)
        a_des = self._a_ref + self._pid.compute_command(self._err, self._v_ref - v, dt)
        self.E[:, self.layout.acc] = J
        self.f[:] = a_des - bias
