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
Variables of the reduced QP and the affine map that recovers joint torques from them.

The reference formulation optimises chi = [base acc, joint acc, base torque, joint torque,
wrenches] subject to the dynamics  M nu_dot + n = S^T tau + J_c^T w.  Torques are a linear function
of the other variables, so the controller solves for x = [nu_dot (nv), w (6 * n_wrenches)] only and
recovers

    tau = T x + t0,   T = [M_a, -J_c,a^T],  t0 = n_a      (rows "a" = actuated joints)

while the unactuated (floating-base) rows stay as an equality constraint  [M_u, -J_c,u^T] x = -n_u.
Every task or constraint written on torques is mapped through (T, t0).

Units: ``variable_scale`` is the size of each variable in physical units, 1 for accelerations and
the robot's weight m g for wrench components; the solver works on x / variable_scale (see
:mod:`orca_ros.optim.solvers.scaled_backend`) and the regularisation weighs wrenches in units of
the robot's weight, so the same defaults hold from a 1 kg arm to a 100 kg humanoid.
"""

from __future__ import annotations

import numpy as np


class ProblemLayout:
    def __init__(self, robot):
        self.robot = robot
        self.nv = robot.get_configuration_space_dimension()
        self.ndof = robot.get_nr_of_degrees_of_freedom()
        self.nbase = self.nv - self.ndof
        self.n_wrenches = 0
        self.contacts = []  # objects owning one wrench each, in wrench order (see set_contacts)
        self.wrench_jacobian = np.zeros(
            (0, self.nv)
        )  # (6 n_wrenches, nv), world-aligned, from the contacts
        self._resize()

    def _resize(self) -> None:
        self.nx = self.nv + 6 * self.n_wrenches
        self.acc = slice(0, self.nv)
        self.base_acc = slice(0, self.nbase)
        self.joint_acc = slice(self.nbase, self.nv)
        self.wrench = slice(self.nv, self.nx)
        self.variable_scale = np.ones(self.nx)
        self.variable_scale[self.wrench] = self.weight_scale()
        self.T_own = np.zeros((self.ndof, self.nx))
        self.t0_own = np.zeros(self.ndof)
        self.T = self.T_own
        self.t0 = self.t0_own

    def weight_scale(self) -> float:
        """Return the robot's weight m g [N] (g = 9.81 whatever the gravity set), at least 1 N."""
        return max(1.0, self.robot.get_total_mass() * 9.81)

    def set_contacts(self, contacts) -> None:
        """
        One external wrench variable per contact (``contact.wrench_index`` set here).

        The QP grows by 6 variables per contact and shrinks back when contacts are removed.
        """
        self.contacts = list(contacts)
        for i, c in enumerate(self.contacts):
            c.wrench_index = i
        self.n_wrenches = len(self.contacts)
        self.wrench_jacobian = np.zeros((6 * self.n_wrenches, self.nv))
        self._resize()

    def wrench_slice(self, index: int) -> slice:
        """Variables of wrench ``index`` in x: [force (3), torque (3)] in world axes."""
        start = self.nv + 6 * index
        return slice(start, start + 6)

    def update(self) -> None:
        """
        Refresh the contacts' Jacobians and (T, t0).

        They come from the robot's current mass matrix and nonlinear effects.
        """
        for i, c in enumerate(self.contacts):
            c.fill_wrench_jacobian(self.wrench_jacobian[6 * i: 6 * i + 6])
        M = self.robot.get_mass_matrix()
        n = self.robot.get_generalized_gravity_and_coriolis_torques()
        nb = self.nbase
        if self.n_wrenches == 0:
            # no copy: views on the model's buffers, valid for this cycle
            self.T = M[nb:] if nb else M
            self.t0 = n[nb:] if nb else n
        else:
            self.T_own[:, : self.nv] = M[nb:]
            self.T_own[:, self.nv:] = -self.wrench_jacobian[:, nb:].T
            self.t0_own[:] = n[nb:]
            self.T, self.t0 = self.T_own, self.t0_own

    def torques(self, x: np.ndarray) -> np.ndarray:
        return self.T @ x + self.t0
