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
Equation of motion  M nu_dot + n = S^T tau + J_c^T w.

The actuated rows are satisfied by construction (torques are recovered from them, see
ProblemLayout); what remains for the solver are the unactuated floating-base rows [M_u, -J_c,u^T] x
= -n_u. A fixed-base robot therefore has no rows here: the dynamics hold exactly and gravity is
always in the torques.
"""

from __future__ import annotations

from .generic_constraint import GenericConstraint


class DynamicsEquationConstraint(GenericConstraint):
    kind = 'equality'

    def rows(self) -> int:
        return self.layout.nbase

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        lay = self.layout
        nb = lay.nbase
        if nb == 0:
            return
        M = self.robot.get_mass_matrix()
        n = self.robot.get_generalized_gravity_and_coriolis_torques()
        self.C[:, lay.acc] = M[:nb]
        if lay.n_wrenches:
            self.C[:, lay.wrench] = -lay.wrench_jacobian[:, :nb].T
        self.lb[:] = -n[:nb]
        self.ub[:] = self.lb
