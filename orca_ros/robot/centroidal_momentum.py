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
    """The terms of one robot model; ``h``, ``Ag``, ``drift``: the arrays terms() fills."""

    def __init__(self, robot):
        self.robot = robot
        self.data = robot.model.createData()
        self._stamp = -1
        nv = robot.model.nv
        self.h, self.drift = np.zeros(6), np.zeros(6)
        self.Ag = np.zeros((6, nv))

    @staticmethod
    def of(robot) -> 'CentroidalMomentum':
        """Return the robot's own, made on first use (again for a new model: a re-weld)."""
        buf = robot.buffers
        if buf.centroidal is None:
            buf.centroidal = CentroidalMomentum(robot)
        return buf.centroidal

    def terms(self):
        """(h 6, A_g 6 x nv, drift A_g_dot nu 6), cached per state; arrays reused."""
        buf = self.robot.buffers
        if self._stamp != buf.stamp:
            q, v = buf.q_pin, buf.v_pin
            dAg = pin.dccrba(self.robot.model, self.data, q, v)
            self.Ag[:] = self.data.Ag
            np.dot(self.Ag, v, out=self.h)
            np.dot(dAg, v, out=self.drift)
            self._stamp = buf.stamp
        return self.h, self.Ag, self.drift
