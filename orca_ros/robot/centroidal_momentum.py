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
The robot's centroidal momentum h = A_g(q) nu and its drift, from Pinocchio (``dccrba``).

h = [m v_com; L]: the linear momentum and the angular momentum about the centre of mass, in
world-aligned axes at the centre of mass (Pinocchio's centroidal frame). Its rate is the sum of
the external wrenches about the centre of mass (the weight's m g in the linear part):
h_dot = A_g nu_dot + A_g_dot nu, with A_g_dot nu the drift. ``dccrba`` computes A_g and A_g_dot in
one pass, on a Data of its own (the cycle's Data keeps what the controller's pass left in it).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


class CentroidalMomentum:
    def __init__(self, robot):
        self.robot = robot
        self.data = robot.model.createData()
        self._stamp = -1
        nv = robot.model.nv
        self._h, self._drift = np.zeros(6), np.zeros(6)
        self._Ag = np.zeros((6, nv))

    @staticmethod
    def of(robot) -> 'CentroidalMomentum':
        """Return the robot's own, made on first use (again for a new model: a re-weld)."""
        if robot._centroidal is None:
            robot._centroidal = CentroidalMomentum(robot)
        return robot._centroidal

    def terms(self):
        """(h 6, A_g 6 x nv, drift A_g_dot nu 6), cached per state; arrays reused."""
        robot = self.robot
        if self._stamp != robot._stamp:
            q, v = robot._q_pin, robot._v_pin
            dAg = pin.dccrba(robot.model, self.data, q, v)
            self._Ag[:] = self.data.Ag
            np.dot(self._Ag, v, out=self._h)
            np.dot(dAg, v, out=self._drift)
            self._stamp = robot._stamp
        return self._h, self._Ag, self._drift
