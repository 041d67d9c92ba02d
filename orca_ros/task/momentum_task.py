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
Centroidal momentum task: A_g nu_dot + A_g_dot nu = h_dot_des, per unit of the robot's mass.

h = A_g(q) nu = [m v_com; L] (linear momentum, angular momentum about the centre of mass, world
axes; :mod:`orca_ros.robot.centroidal_momentum`), its desired rate from a PI servo on h:

    h_dot_des = h_dot_ref + Kp (h_ref - h) + Ki integral(h_ref - h) dt

Kp [1/s] makes the momentum's error decay (alone, as exp(-Kp t)); the integral of the linear
part's error is m times the CoM's offset from the path h_ref describes, so Ki there acts as a CoM
position gain; for the angular part it has no such meaning and defaults to 0. The rows are divided
by the robot's mass: the linear part is then the CoM's acceleration, on the scale of a
:class:`~orca_ros.task.com_task.CoMTask` (the same default weight means as much).

The common use is the angular part only (``set_selection_vector([0, 0, 0, 1, 1, 1])``): damping
the angular momentum a push or a fast arm motion gives the body (TSID's angular momentum task,
OpenSoT's and mc_rtc's momentum tasks). Default: h_ref = 0, Kp = 10 1/s, all six rows.
"""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask
from ..servo.pid_controller import PIDController


class MomentumTask(GenericTask):
    def __init__(self, name: str):
        super().__init__(name)
        self._pid = PIDController(6)
        self._pid.set_proportional_gain(10.0)
        self._h_ref = np.zeros(6)
        self._hd_ref = np.zeros(6)
        self._err = np.zeros(6)
        self._none = np.zeros(6)  # no derivative term: the momentum's rate is not measured

    def rows(self) -> int:
        return 6

    def pid(self) -> PIDController:
        """Return the servo: proportional gain on h's error, integral gain on its integral."""
        return self._pid

    def set_desired(self, momentum=None, rate=None) -> None:
        """Desired momentum h_ref = [m v_com; L] and its rate (6 values each; default 0)."""
        vals = []
        for what, x in (('momentum', momentum), ('momentum rate', rate)):
            a = np.zeros(6) if x is None else np.asarray(x, dtype=float).reshape(-1)
            if a.shape != (6,) or not np.all(np.isfinite(a)):
                raise ValueError(f"task '{self.name}': desired {what} must be 6 finite values")
            vals.append(a)
        self._h_ref[:], self._hd_ref[:] = vals

    def get_desired(self):
        return self._h_ref.copy(), self._hd_ref.copy()

    def get_current_momentum(self) -> np.ndarray:
        return self.robot.get_centroidal_momentum_terms()[0].copy()

    def get_momentum_error(self) -> np.ndarray:
        """h_ref - h at the last update."""
        return self._err.copy()

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        robot = self.robot
        h, Ag, drift = robot.get_centroidal_momentum_terms()
        np.subtract(self._h_ref, h, out=self._err)
        hd_des = self._hd_ref + self._pid.compute_command(self._err, self._none, dt)
        inv_m = 1.0 / robot.get_total_mass()
        self.E[:, self.layout.acc] = Ag * inv_m
        np.subtract(hd_des, drift, out=self.f)
        self.f *= inv_m
