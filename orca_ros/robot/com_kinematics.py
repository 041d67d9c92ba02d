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
Centre of mass of the whole robot, in the world frame.

position, Jacobian, velocity and bias J_dot nu.

The position, velocity and Jacobian are the ones Pinocchio's ``computeAllTerms`` already left
in the robot's main Data for this state. The bias comes from a zero-acceleration pass on this
object's own Data (on the main Data it would overwrite the frame quantities of the same state).
Cached per state.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


class ComKinematics:
    def __init__(self, robot):
        self.robot = robot
        self.data = robot.model.createData()
        self._stamp = -1
        self._terms = None
        self._zero = np.zeros(robot.model.nv)
        self.mass = float(pin.computeTotalMass(robot.model))

    def terms(self):
        """(position 3, Jacobian 3 x nv, velocity 3, bias acceleration 3) in world axes."""
        robot = self.robot
        buf = robot.buffers
        if self._stamp == buf.stamp and self._terms is not None:
            return self._terms
        robot.update_terms()  # computeAllTerms: com, vcom and Jcom in the main Data
        main = robot.data
        pin.centerOfMass(robot.model, self.data, buf.q_pin, buf.v_pin, self._zero)
        self._terms = (
            main.com[0].copy(), main.Jcom.copy(), main.vcom[0].copy(), self.data.acom[0].copy()
        )
        self._stamp = buf.stamp
        return self._terms
