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
Whole-body dynamics of a :class:`~orca_ros.robot.robot_model.RobotModel` at its current state.

The mass matrix, gravity, Coriolis, centre of mass and centroidal momentum. Each getter reads
Pinocchio's terms of the current state, computed once per state (the robot's ``update_terms``;
its own Data for gravity alone).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .centroidal_momentum import CentroidalMomentum
from .com_kinematics import ComKinematics


class DynamicsApiMixin:
    """The dynamics getters of RobotModel (see the module)."""

    def get_mass_matrix(self) -> np.ndarray:
        """Generalized mass matrix (nv x nv); a view valid until the next state change."""
        self.update_terms()
        return self.data.M

    def get_generalized_gravity_and_coriolis_torques(self) -> np.ndarray:
        self.update_terms()
        return self.data.nle

    def get_generalized_gravity_torques(self) -> np.ndarray:
        buf = self.buffers
        if buf is None or not buf.initialized:
            self._require_model()
            raise RuntimeError(
                f"robot '{self.name}' has no state yet: call set_robot_state() first"
            )
        if self._gravity_stamp != buf.stamp:
            self._g = pin.computeGeneralizedGravity(
                self.model, self._gravity_data, buf.q_pin
            ).copy()
            self._gravity_stamp = buf.stamp
        return self._g

    def get_joint_gravity_torques(self) -> np.ndarray:
        return self.get_generalized_gravity_torques()[self.nbase:].copy()

    def get_joint_gravity_and_coriolis_torques(self) -> np.ndarray:
        return self.get_generalized_gravity_and_coriolis_torques()[self.nbase:].copy()

    def get_joint_coriolis_torques(self) -> np.ndarray:
        return (
            self.get_generalized_gravity_and_coriolis_torques()
            - self.get_generalized_gravity_torques()
        )[self.nbase:].copy()

    def _com_kinematics(self) -> ComKinematics:
        self._require_model()
        buf = self.buffers
        if buf.com is None:
            buf.com = ComKinematics(self)
        return buf.com

    def get_center_of_mass_terms(self):
        """
        (position, jacobian 3 x nv, velocity, bias J_dot nu) of the centre of mass.

        World axes.
        """
        return self._com_kinematics().terms()

    def get_centroidal_momentum_terms(self):
        """
        (h, A_g 6 x nv, drift A_g_dot nu) of the centroidal momentum h = A_g nu.

        h = [m v_com; angular momentum about the CoM], world-aligned axes at the CoM.
        """
        self._require_model()
        return CentroidalMomentum.of(self).terms()

    def get_center_of_mass(self) -> np.ndarray:
        return self.get_center_of_mass_terms()[0].copy()

    def get_total_mass(self) -> float:
        return self._com_kinematics().mass
