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
A priority level below others, solved *relative* to the solution of the level just above.

With x_ref the solution of the level above, the level solves for the step z = x - x_ref:

* the tasks of the levels above are *locked*: their rows diag(s) E_i keep the value they had at
  x_ref, either exactly (strict priority: z lives in the null space of every locked row and of the
  constraint equalities, x = x_ref + N y, with N an orthonormal basis from an SVD, so the locks
  cost no equality row and can never conflict with an inequality) or up to a per-row band |diag(s)
  E_i z| <= band (the generalized priorities of :mod:`orca_ros.optim.generalized`);
* every inequality and bound of the original problem is kept, relaxed only so that z = 0 stays
  feasible: l' = min(l - C x_ref, 0), u' = max(u - C x_ref, 0). x_ref satisfies the constraints to
  the tolerance of the solver that produced it; without this relaxation a level above sitting on a
  limit (e.g. a task that cannot be achieved within the torque limits) leaves the levels below a
  problem that a solver may call infeasible by a rounding error. With it, each lower level is
  feasible by construction, never makes a constraint worse than the level above left it, and the
  residuals reached above are kept whatever they are (achieved or not): the "slack" of an
  unachievable level is frozen at its optimum.
"""

from __future__ import annotations

import math

import numpy as np

from .solvers import make_backend, ReturnCode
from .weighted_problem import WeightedProblem

_RANK_TOL = 1e-9  # singular values below this (relative to the largest, at least 1) count as zero
_EMPTY_ROW = 1e-10  # projected rows shorter than this are empty (their unit rows have norm ~1)
_ROOM_TOL = 1e-6  # bounds closer than this to the level above's solution leave the step no room


class LowerLevelProblem(WeightedProblem):
    def __init__(
        self, plan, cost_rows: slice, solver, level: int, locked_tasks, diagonal_tasks=()
    ):
        super().__init__(
            plan,
            cost_rows,
            solver,
            level=level,
            locked_tasks=locked_tasks,
            diagonal_tasks=diagonal_tasks,
        )
        nx = plan.layout.nx
        n_lock = self.n_eq - self.n_eq_constraints
        self.x_ref = np.zeros(nx)
        self.band: np.ndarray | None = None  # None: strict locks
        # strict form: variables y (nx, padded), rows [C N; N] (inequalities and bounds on x)
        self._N = np.zeros((nx, nx))
        self._Hs = np.zeros((nx, nx))
        self._gs = np.zeros(nx)
        self._Cs = np.zeros((self.n_in + nx, nx))
        self._ls = np.zeros(self.n_in + nx)
        self._us = np.zeros(self.n_in + nx)
        self._free = np.full(nx, np.inf)
        self.strict_backend = make_backend(solver, nx, 0, self.n_in + nx, box=False)
        scale = plan.layout.variable_scale
        self._scale = None if np.all(scale == 1.0) else scale
        self._As = np.zeros((self.n_eq, nx))
        self._damp_w = 1.0 / np.square(scale)  # temporal damping per variable: wrenches in m g
        # banded form: variables z (nx), equalities A_eq z = 0, rows [C; locks], bounds on z
        self._Ab = np.zeros((self.n_eq_constraints, nx))
        self._bb = np.zeros(self.n_eq_constraints)
        self._Cb = np.zeros((self.n_in + n_lock, nx))
        self._lb = np.zeros(self.n_in + n_lock)
        self._ub = np.zeros(self.n_in + n_lock)
        self._lboxb = np.zeros(nx)
        self._uboxb = np.zeros(nx)
        self.banded_backend = None
        self.null_space_dimension = nx
        # temporal damping mu ||x - x_prev||^2 (see set_temporal_damping); x_prev: this level's
        # solution of the previous cycle
        self.temporal_damping = 0.0
        self._x_prev: np.ndarray | None = None

    def set_temporal_damping(self, mu: float) -> None:
        """
        Pull this level's solution towards its previous cycle's: + mu ||x - x_prev||^2.

        A lower level whose tasks conflict with the levels above sits on the bounds left to it, and
        hops between vertices of that set as bounds come and go (a velocity limit riding on and
        off): its accelerations jump by tens of rad/s^2 from one cycle to the next. The damping
        makes it move continuously; it acts in the null space of the locked rows only, so the
        levels above are untouched. 0 (default) solves each cycle on its own. Wrenches are damped
        in units of the robot's weight (as the solver sees them). A level's first cycle (and the
        first after a failure) is damped towards the solution of the level above, so that a level
        switched on starts from what the robot already does.
        """
        mu = float(mu)
        if not (np.isfinite(mu) and mu >= 0.0):
            raise ValueError(f'temporal damping must be finite and >= 0, got {mu}')
        self.temporal_damping = mu
        if mu == 0.0:
            self._x_prev = None

    def backends(self):
        return [self.strict_backend, self.banded_backend]

    def _make_backend(self):
        return None  # the level's own back-ends are made in __init__ (strict / banded forms)

    def lock(self, x_above: np.ndarray, band: np.ndarray | None = None) -> None:
        """
        Keep the locked rows at their value at x_above.

        Exactly (band None or all zero) or to +-band.

        A locked task that is ramping in or out (activation factor rho in (0, 1)) is released
        progressively: its rows get the band  (1 - rho) / rho * (|s E x_above| + |s f| + 1),  0
        when fully active and growing without bound as the task fades, so that switching a
        higher-level task off (or on) moves the levels below continuously instead of dropping (or
        imposing) a lock at once.
        """
        super().lock(x_above)
        self.x_ref[:] = x_above
        k = 0
        for t in self.locked:
            m = t.rows()
            rho = t.get_ramp_value() if t.is_computing() else 0.0
            if 0.0 < rho < 1.0 and t.get_effective_weight() > 0.0:
                if band is None:
                    band = np.zeros(self.lock_rows())
                lock_value = self.b[
                    self.n_eq_constraints + k: self.n_eq_constraints + k + m
                ]  # s E x_above
                scale = (np.abs(lock_value) + np.abs(t.selection * t.f) + 1.0) * (t.selection > 0)
                np.maximum(band[k: k + m], (1.0 - rho) / rho * scale, out=band[k: k + m])
            k += m
        if band is not None and not np.any(band > 0.0):
            band = None
        self.band = band

    # -------------------------------------------------------------- solve
    def solve(self) -> ReturnCode:
        if not math.isfinite(self.H.sum() + self.g.sum()):
            self.return_code = ReturnCode.NON_FINITE_PROBLEM
            return self.return_code
        mu, prev = self.temporal_damping, self._x_prev
        if prev is None:
            # first cycle (or after a failure): towards the level above's solution, so that a level
            # starts from what the robot is already doing instead of jumping to its optimum
            prev = self.x_ref
        if mu > 0.0:  # + mu ||(x - x_prev) / d||^2 (the solver's units), undone after the solve
            mw = mu * self._damp_w
            self._diag += mw
            self.g -= mw * prev
        try:
            code, dx = self._solve_strict() if self.band is None else self._solve_banded()
        finally:
            if mu > 0.0:
                self._diag -= mw
                self.g += mw * prev
        if code is ReturnCode.SUCCESS:
            if np.isfinite(dx.sum()):
                np.add(self.x_ref, dx, out=self.x)
            else:
                code = ReturnCode.NON_FINITE_SOLUTION
        if mu > 0.0:
            if code is ReturnCode.SUCCESS:
                if self._x_prev is None:
                    self._x_prev = self.x.copy()
                else:
                    self._x_prev[:] = self.x
            else:
                self._x_prev = None  # after a failure, start again from the next solution
        self.return_code = code
        return code

    def _relaxed(self, lo, hi, value, out_lo, out_hi) -> None:
        # room left to the step z, less _ROOM_TOL: the level above meets its bounds only to its
        # solver's accuracy, and a row that barely touches the null space (norm ~1e-4) turns such
        # a crumb of room into a large motion; a room of 4e-7 rad/s^2 on a joint resting on its
        # box bound let the posture level move 31 rad/s^2 along the null space, then nothing the
        # next cycle (a 3.3 Nm step); less the tolerance, the room is 0 then and grows
        # continuously
        np.subtract(lo, value, out=out_lo)
        out_lo += _ROOM_TOL
        np.minimum(out_lo, 0.0, out=out_lo)
        np.subtract(hi, value, out=out_hi)
        out_hi -= _ROOM_TOL
        np.maximum(out_hi, 0.0, out=out_hi)

    def _solve_strict(self):
        nx, n_in = self.layout.nx, self.n_in
        N = self._N
        N.fill(0.0)
        d = self._scale
        if self.n_eq:
            # the null space in the solver's units (x = D x~, see solvers/scaled_backend.py)
            A = self.A if d is None else np.multiply(self.A, d, out=self._As)
            _, s, vt = np.linalg.svd(A, full_matrices=True)
            r = int(np.count_nonzero(s > _RANK_TOL * max(1.0, s[0] if s.size else 0.0)))
        else:
            vt, r = np.eye(nx), 0
        k = nx - r
        self.null_space_dimension = k
        if k == 0:  # the levels above use every degree of freedom: nothing left to optimise
            return ReturnCode.SUCCESS, np.zeros(nx)
        N[:, :k] = vt[r:].T
        if d is not None:
            N *= d[:, None]  # x - x_ref = D N~ y
        HN = self.H @ N
        np.dot(N.T, HN, out=self._Hs)
        self._Hs[range(k, nx), range(k, nx)] = 1.0  # padding variables: zero columns, pinned at 0
        np.dot(N.T, self.H @ self.x_ref + self.g, out=self._gs)
        if n_in:
            np.dot(self.C, N, out=self._Cs[:n_in])
            self._relaxed(self.l, self.u, self.C @ self.x_ref, self._ls[:n_in], self._us[:n_in])
        self._Cs[n_in:] = N
        self._relaxed(self.lbox, self.ubox, self.x_ref, self._ls[n_in:], self._us[n_in:])
        # rows of very different scales (torques, accelerations, projected onto N) slow the solvers
        # down on these often degenerate problems: normalise them (empty rows are always satisfied)
        norms = np.linalg.norm(self._Cs, axis=1)
        # a row orthogonal to the null space (a joint the levels above fix entirely) is rounding
        # noise (~1e-16): normalised, its sign would cut the step's space in half at random (a
        # posture level stopped dead for one cycle: a 3.5 Nm step); it constrains nothing
        empty = norms < _EMPTY_ROW
        norms[empty] = 1.0
        self._Cs /= norms[:, None]
        self._ls /= norms
        self._us /= norms
        if empty.any():
            self._Cs[empty] = 0.0
            self._ls[empty] = -np.inf
            self._us[empty] = np.inf
        code = self.strict_backend.solve(
            self._Hs, self._gs, None, None, self._Cs, self._ls, self._us, -self._free, self._free
        )
        if code is not ReturnCode.SUCCESS:
            return code, None
        return code, N @ self.strict_backend.x

    def _solve_banded(self):
        nx, n_in, ne = self.layout.nx, self.n_in, self.n_eq_constraints
        if self.banded_backend is None:
            self.banded_backend = make_backend(
                self.solver_type, nx, ne, self._Cb.shape[0], scale=self.layout.variable_scale
            )
            self.banded_backend.deadline = self.strict_backend.deadline
            self.banded_backend.max_iterations = self.strict_backend.max_iterations
        self._Ab[:] = self.A[
            :ne
        ]  # x_ref satisfies the equalities: keep them as they are (A z = 0)
        g = self.H @ self.x_ref + self.g
        if n_in:
            self._Cb[:n_in] = self.C
            self._relaxed(self.l, self.u, self.C @ self.x_ref, self._lb[:n_in], self._ub[:n_in])
        self._Cb[n_in:] = self.A[ne:]
        np.negative(self.band, out=self._lb[n_in:])
        self._ub[n_in:] = self.band
        self._relaxed(self.lbox, self.ubox, self.x_ref, self._lboxb, self._uboxb)
        code = self.banded_backend.solve(
            self.H, g, self._Ab, self._bb, self._Cb, self._lb, self._ub, self._lboxb, self._uboxb
        )
        return code, (self.banded_backend.x if code is ReturnCode.SUCCESS else None)

    def lock_rows(self) -> int:
        return self.n_eq - self.n_eq_constraints
