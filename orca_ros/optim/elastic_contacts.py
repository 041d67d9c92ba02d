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
lasted (a quadruped pushed hard failed cycle after cycle and fell). Here the failed
cycle is solved once more with the contacts' existence conditions (J nu_dot + J_dot nu = -k J nu)
turned into a least-squares term of weight ``weight`` (accelerations of the contact points, m/s^2):
the contacts slip only as much as the other constraints demand, their wrenches stay in their cones
and the dynamics and torque limits stay exact. ``Controller.contacts_relaxed()`` tells a cycle
solved so; the levels below the first keep its solution for that cycle.

What a robot in mid-fall cannot keep either is elastic too, through one slack variable per row
whose square is penalised (the row may be violated, at a cost): the rows of constraints marked
``elastic`` (the balance constraint: a CoM already past an edge of the support polygon cannot be
brought back at the rate it asks; weight ``balance_weight``, CoM accelerations in m/s^2, lighter
than the contacts': the robot gives up the CoM's bound before it lets a foot slip) and the joint
position and velocity limits' acceleration bounds (weight ``weight``, joint accelerations: a leg
braking at its limit may need more torque than it has). Dynamics, torque limits, friction cones,
wrench bounds and hard acceleration limits stay exact: zero wrenches and torques satisfy them, so
the elastic problem always has a solution, and the controller keeps commanding through a fall.

It is solved by an active-set method whatever solver the controller runs: DAQP where installed,
else ProxQP. Its cost mixes weights 1e4 and 1e-4, which first-order methods do not resolve: on the
quadruped pushed from behind, OSQP reached its iteration cap on every elastic cycle, and with more
iterations still stopped far from DAQP's solution, while DAQP solved them all and ProxQP agreed
with it closely.
"""

from __future__ import annotations

import numpy as np

from .solvers import installed, make_backend, QPSolver, ReturnCode
from ..constraint.contact import ContactExistenceCondition

DEFAULT_WEIGHT = 1e4
DEFAULT_BALANCE_WEIGHT = 1e2
# a little of every variable in the cost: the wrench block is nearly singular, and DAQP called
# feasible elastic problems of a robot in mid-fall infeasible without it
REGULARISATION = 1e-4


def elastic_solver(solver) -> QPSolver:
    """Pick the solver of the elastic problem: an active-set one where installed (see above)."""
    for s in (QPSolver.DAQP, QPSolver.PROXQP):
        if installed(s):
            return s
    return solver


class ElasticContacts:
    def __init__(
        self,
        plan,
        solver,
        weight: float = DEFAULT_WEIGHT,
        balance_weight: float = DEFAULT_BALANCE_WEIGHT,
    ):
        self.plan = plan
        self.weight = float(weight)
        layout = plan.layout
        nx, n_in = layout.nx, plan.n_in
        soft = np.zeros(plan.n_eq, dtype=bool)
        for c, rows in zip(plan.eq, plan.eq_rows):
            if isinstance(c, ContactExistenceCondition):
                soft[rows] = True
        self.available = bool(soft.any())
        self._soft = np.flatnonzero(soft)
        self._hard = np.flatnonzero(~soft)
        elastic = np.zeros(n_in, dtype=bool)
        for c, rows in zip(plan.ineq, plan.in_rows):
            elastic[rows] = bool(getattr(c, 'elastic', False))
        rows_in = np.flatnonzero(elastic)
        self._joints = np.arange(nx)[layout.joint_acc] if plan.soft_box else np.zeros(0, int)
        nj = self._joints.size
        ns = rows_in.size + nj  # slack variables: elastic rows, then soft joint bounds
        nz = nx + ns
        self.H = np.zeros((nz, nz))
        self._Hx = np.zeros((nx, nx))
        self.g = np.zeros(nz)
        self.A = np.zeros((self._hard.size, nz))
        self.b = np.zeros(self._hard.size)
        self.C = np.zeros((n_in + nj, nz))
        self.C[rows_in, nx + np.arange(rows_in.size)] = 1.0
        self.C[n_in + np.arange(nj), self._joints] = 1.0
        self.C[n_in + np.arange(nj), nx + rows_in.size + np.arange(nj)] = 1.0
        self.lo = np.zeros(n_in + nj)
        self.hi = np.zeros(n_in + nj)
        self.lbox = np.full(nz, -np.inf)
        self.ubox = np.full(nz, np.inf)
        slack = np.arange(nx, nz)
        self.H[slack, slack] = np.concatenate(
            (np.full(rows_in.size, float(balance_weight)), np.full(nj, self.weight))
        )
        self.x = np.zeros(nx)
        scale = np.concatenate((layout.variable_scale, np.ones(ns)))
        self.backend = (
            make_backend(elastic_solver(solver), nz, self._hard.size, n_in + nj, scale=scale)
            if self.available
            else None
        )

    def _hard_joint_box(self):
        """Bound the joints by the hard box constraints alone (the soft ones are rows here)."""
        lo, hi = self.lbox[self._joints], self.ubox[self._joints]
        lo.fill(-np.inf)
        hi.fill(np.inf)
        for c in self.plan.hard_box:
            if c.is_computing():
                np.maximum(lo, c.lb, out=lo)
                np.minimum(hi, c.ub, out=hi)
        self.lbox[self._joints], self.ubox[self._joints] = lo, hi

    def solve(self, problem, deadline, max_iterations) -> ReturnCode:
        """Solve ``problem`` (level 0, built) with contacts, balance and joint bounds elastic."""
        plan, w = self.plan, self.weight
        nx, n_in = plan.layout.nx, plan.n_in
        Ae, be = plan.A[self._soft], plan.b[self._soft]
        np.dot(Ae.T, Ae, out=self._Hx)
        self._Hx *= w
        self._Hx += problem.H
        self._Hx.flat[:: nx + 1] += REGULARISATION
        self.H[:nx, :nx] = self._Hx
        np.dot(Ae.T, be, out=self.g[:nx])
        self.g[:nx] *= -w
        self.g[:nx] += problem.g
        self.A[:, :nx] = plan.A[self._hard]
        np.take(plan.b, self._hard, out=self.b)
        self.C[:n_in, :nx] = plan.C
        self.lo[:n_in], self.hi[:n_in] = plan.l, plan.u
        self.lbox[:nx], self.ubox[:nx] = plan.lbox, plan.ubox
        if self._joints.size:
            self.lo[n_in:], self.hi[n_in:] = plan.lbox[self._joints], plan.ubox[self._joints]
            self._hard_joint_box()
        b = self.backend
        b.deadline = deadline
        b.max_iterations = max_iterations or b.default_max_iterations
        code = b.solve(
            self.H, self.g, self.A, self.b, self.C, self.lo, self.hi, self.lbox, self.ubox
        )
        if code is ReturnCode.SUCCESS:
            if np.isfinite(b.x.sum()):
                self.x[:] = b.x[:nx]
            else:
                code = ReturnCode.NON_FINITE_SOLUTION
                b.reset()
        return code
