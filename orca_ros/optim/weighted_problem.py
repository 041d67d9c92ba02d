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
One weighted QP level: tasks summed with their (ramped) weights, all constraints applied.

In a strict hierarchy a level also receives the tasks of every level above it as *locked* tasks:
rows diag(s) E x = diag(s) E x*, with x* the solution of the level just above (see
:mod:`.lower_level_problem`, which solves such a level relative to x*; here the rows only describe
the problem, e.g. for a KKT solve).

Sizes, row offsets and the solver's sparsity pattern are fixed when the problem is created (at
configuration time), on the rows of the controller's :class:`~orca_ros.optim.cycle_plan.CyclePlan`;
:meth:`build` only forms the Hessian and gradient of this level from them.
"""

from __future__ import annotations

import math

import numpy as np

from ..optim.solvers import make_backend, ReturnCode
from ..utils.logger import get_logger

_LOG = get_logger('optim')


class WeightedProblem:
    def __init__(
        self, plan, cost_rows: slice, solver, level: int = 0, locked_tasks=(), diagonal_tasks=()
    ):
        """
        Make a level whose cost is the plan's dense task rows ``cost_rows``.

        Its ``diagonal_tasks`` and the global regularisation, under every constraint of the plan;
        ``locked_tasks``: tasks of the levels above kept at their value (lower levels).
        """
        self.plan = plan
        self.layout = layout = plan.layout
        self.level = level
        self.locked = list(locked_tasks)
        self.solver_type = solver
        nx = layout.nx
        self.n_eq_constraints = plan.n_eq
        k = plan.n_eq
        self._lock_rows = []
        for t in self.locked:
            self._lock_rows.append(slice(k, k + t.rows()))
            k += t.rows()
        self.n_eq = k
        self.n_in = plan.n_in
        self.H = np.zeros((nx, nx))
        self.g = np.zeros(nx)
        self._diag = self.H.reshape(-1)[:: nx + 1]  # view on the diagonal
        if self.locked:  # the constraint rows are copied in front of the lock rows at every build
            self.A = np.zeros((self.n_eq, nx))
            self.b = np.zeros(self.n_eq)
        else:
            self.A, self.b = plan.A, plan.b
        self.C, self.l, self.u = plan.C, plan.l, plan.u
        self.lbox, self.ubox = plan.lbox, plan.ubox
        # views on this level's rows of the plan, and the product buffer W E
        self._E, self._f = plan.E[cost_rows], plan.f[cost_rows]
        self._w = plan.w[cost_rows][:, None]
        self._WE = np.zeros(self._E.shape)
        self._diagonal = [
            (t.diagonal_columns, plan.ws[id(t)], plan.wsf[id(t)])
            for t in [plan.regularisation] + list(diagonal_tasks)
        ]
        self.backend = self._make_backend()
        self.stacked = not self.locked and hasattr(self.backend, 'solve_stacked')
        self.x = np.zeros(nx)
        self.return_code = ReturnCode.NOT_SOLVED
        # True when the compiled cycle forms H and g (optim/compiled/plan_assembly.py), which
        # then tells whether they are finite
        self.prebuilt = False
        self.built_finite = True

    def _make_backend(self):
        lay = self.layout
        return make_backend(
            self.solver_type, lay.nx, self.n_eq, self.n_in, scale=lay.variable_scale
        )

    def backends(self):
        return [self.backend]

    def set_budget(self, deadline: float | None, max_iterations: int | None = None) -> None:
        """Deadline (time.perf_counter() instant) and iteration cap of this level's next solve."""
        for b in self.backends():
            if b is not None:
                b.deadline = deadline
                b.max_iterations = max_iterations or b.default_max_iterations

    def lock(self, x_above: np.ndarray) -> None:
        """
        Keep the residuals the higher levels reached at x_above.

        Their tasks' E, f of this cycle.
        """
        for t, rows in zip(self.locked, self._lock_rows):
            if t.get_effective_weight() > 0.0:
                np.multiply(t.E, t.selection[:, None], out=self.A[rows])
                np.dot(self.A[rows], x_above, out=self.b[rows])
            else:
                self.A[rows] = 0.0
                self.b[rows] = 0.0

    # -------------------------------------------------------------- build
    def build(self) -> None:
        """
        H = E^T W E + w_r I.

        G = -E^T W f - w_r f_r over this level's stacked rows (W, the row weights).
        """
        if self.prebuilt:
            return
        H, g = self.H, self.g
        if self._E.shape[0]:
            np.multiply(self._E, self._w, out=self._WE)
            np.dot(self._WE.T, self._E, out=H)
            np.dot(self._WE.T, self._f, out=g)
            np.negative(g, out=g)
        else:
            H.fill(0.0)
            g.fill(0.0)
        diag = self._diag
        for cols, ws, wsf in self._diagonal:
            diag[cols] += ws
            g[cols] -= wsf
        if self.locked:
            nc = self.n_eq_constraints
            self.A[:nc] = self.plan.A
            self.b[:nc] = self.plan.b

    # -------------------------------------------------------------- solve
    def solve(self) -> ReturnCode:
        # states, targets, gains and limits are validated where they enter; the matrices built from
        # them are finite unless a task computed garbage, which shows in the cost
        if not (
            self.built_finite if self.prebuilt else math.isfinite(self.H.sum() + self.g.sum())
        ):
            self.return_code = ReturnCode.NON_FINITE_PROBLEM
            return self.return_code
        if self.stacked:  # the plan's arrays are already in the solver's layout
            code = self.backend.solve_stacked(
                self.H, self.g, self.plan.M, self.plan.lo, self.plan.hi
            )
        else:
            code = self.backend.solve(
                self.H, self.g, self.A, self.b, self.C, self.l, self.u, self.lbox, self.ubox
            )
        x = self.backend.x
        # a back-end that writes into this level's x (the compiled cycle's DAQP) checked it
        if code is ReturnCode.SUCCESS and x is not self.x:
            if not math.isfinite(x.sum()):
                code = ReturnCode.NON_FINITE_SOLUTION
                self.backend.reset()
            else:
                self.x[:] = x
        self.return_code = code
        return code

    def solve_equality_only(self) -> np.ndarray:
        """Closed-form KKT solution of the problem without its inequality and box constraints."""
        nx, ne = self.layout.nx, self.n_eq
        K = np.zeros((nx + ne, nx + ne))
        K[:nx, :nx] = self.H
        K[:nx, nx:] = self.A.T
        K[nx:, :nx] = self.A
        rhs = np.concatenate((-self.g, self.b))
        try:
            sol = np.linalg.solve(K, rhs)
        except np.linalg.LinAlgError:
            sol = np.linalg.lstsq(K, rhs, rcond=None)[0]
        return sol[:nx]

    def max_constraint_violation(self, x: np.ndarray) -> float:
        """Largest violation of every constraint of this problem at x."""
        v = 0.0
        if self.n_eq:
            v = max(v, float(np.max(np.abs(self.A @ x - self.b))))
        if self.n_in:
            y = self.C @ x
            v = max(
                v, float(np.max(self.l - y, initial=0.0)), float(np.max(y - self.u, initial=0.0))
            )
        v = max(
            v, float(np.max(self.lbox - x, initial=0.0)), float(np.max(x - self.ubox, initial=0.0))
        )
        return v
