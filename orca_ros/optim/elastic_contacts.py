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
Elastic contacts: when the QP with rigid contacts has no solution, let the contacts slip.

A hard push can leave no acceleration that keeps every contact point still within the friction
cones, torque and joint limits: the feet are already sliding, or the legs are at their limits. The
problem is then infeasible and, before, the controller held its last command for as long as that
lasted (a quadruped pushed with 150 N for 0.1 s failed ~2000 cycles and fell). Here the failed
cycle is solved once more with the contacts' existence conditions (J nu_dot + J_dot nu = -k J nu)
turned into a least-squares term of weight ``weight`` (accelerations of the contact points, m/s^2):
the contacts slip only as much as the other constraints demand, their wrenches stay in their cones
and the dynamics, torque and joint limits stay exact. ``Controller.contacts_relaxed()`` tells a
cycle solved so; the levels below the first keep its solution for that cycle.
"""

from __future__ import annotations

import numpy as np

from .solvers import make_backend, ReturnCode
from ..constraint.contact import ContactExistenceCondition

DEFAULT_WEIGHT = 1e4


class ElasticContacts:
    def __init__(self, plan, solver, weight: float = DEFAULT_WEIGHT):
        self.plan = plan
        self.weight = float(weight)
        nx = plan.layout.nx
        soft = np.zeros(plan.n_eq, dtype=bool)
        for c, rows in zip(plan.eq, plan._eq_rows):
            if isinstance(c, ContactExistenceCondition):
                soft[rows] = True
        self.available = bool(soft.any())
        self._soft = np.flatnonzero(soft)
        self._hard = np.flatnonzero(~soft)
        self.H = np.zeros((nx, nx))
        self.g = np.zeros(nx)
        self.A = np.zeros((self._hard.size, nx))
        self.b = np.zeros(self._hard.size)
        self.x = np.zeros(nx)
        self.backend = (
            make_backend(solver, nx, self._hard.size, plan.n_in, scale=plan.layout.variable_scale)
            if self.available
            else None
        )

    def solve(self, problem, deadline, max_iterations) -> ReturnCode:
        """Solve ``problem`` (level 0, already built) with its existence conditions elastic."""
        plan, w = self.plan, self.weight
        Ae, be = plan.A[self._soft], plan.b[self._soft]
        np.dot(Ae.T, Ae, out=self.H)
        self.H *= w
        self.H += problem.H
        np.dot(Ae.T, be, out=self.g)
        self.g *= -w
        self.g += problem.g
        np.take(plan.A, self._hard, axis=0, out=self.A)
        np.take(plan.b, self._hard, out=self.b)
        b = self.backend
        b.deadline = deadline
        b.max_iterations = max_iterations or b.default_max_iterations
        code = b.solve(
            self.H, self.g, self.A, self.b, plan.C, plan.l, plan.u, plan.lbox, plan.ubox
        )
        if code is ReturnCode.SUCCESS:
            if np.isfinite(b.x.sum()):
                self.x[:] = b.x
            else:
                code = ReturnCode.NON_FINITE_SOLUTION
                b.reset()
        return code
