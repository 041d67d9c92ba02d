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
  x_ref, either exactly (strict priority: diag(s) E_i z = 0, with the constraint equalities
  A z = 0; DAQP takes them as equality rows, made orthonormal first (:func:`orthonormalise_locks`:
  DAQP declares a feasible problem infeasible when its equalities depend on each other, as the
  3 rows of an elbow's position do where its Jacobian loses rank); ProxQP and OSQP work in a
  null-space basis instead, see :mod:`.null_space_step`) or up to a
  per-row band |diag(s) E_i z| <= band (the generalized priorities of
  :mod:`orca_ros.optim.generalized`);
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

from .null_space_step import NullSpaceStep
from .solvers import make_backend, QPSolver, ReturnCode
from .weighted_problem import WeightedProblem

_ROOM_TOL = 1e-6  # bounds closer than this to the level above's solution leave the step no room
#: a lock row whose part independent of the rows before it is below this share of the largest
#: lock row is left out (zero: the unselected components' rows, directions a singular task loses)
LOCK_RANK_TOL = 1e-6


def orthonormalise_locks(rows: np.ndarray) -> None:
    """
    Replace the lock rows by an orthonormal basis of the space they span, in place.

    Modified Gram-Schmidt in row order; a row that depends on the ones before it (to
    LOCK_RANK_TOL) becomes zero. The same equalities z-wise (rows . z = 0), independent.
    """
    if not rows.shape[0]:
        return
    tol = LOCK_RANK_TOL * math.sqrt(float(np.einsum('ij,ij->i', rows, rows).max()))
    kept = []
    for i in range(rows.shape[0]):
        r = rows[i]
        for j in kept:
            r -= (r @ rows[j]) * rows[j]
        n = math.sqrt(float(r @ r))
        if n > tol and n > 0.0:
            r /= n
            kept.append(i)
        else:
            r[:] = 0.0


#: the default temporal damping of the levels below the first (a ratio, see set_temporal_damping):
#: strict and GENERALIZED torques without steps on arms nobody tuned for (the lwr, iiwa and Panda
#: 3-level stack of test/test_lower_level_damping.py), for about this many cycles of lag on a
#: level that follows its optimum
DEFAULT_LOWER_LEVEL_DAMPING = 10.0


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
        # strict form: variables z (nx), equalities [A_eq; locks] z = 0, rows C, bounds on z
        # (DAQP); for the other solvers, in a null-space basis (see null_space_step.py)
        scale = plan.layout.variable_scale
        ne, ni = self.n_eq, self.n_in
        if solver is QPSolver.DAQP:
            self.locked_backend = make_backend(solver, nx, ne, ni, scale=scale)
            self.null_space = None
            self._retry = None  # a null-space solve for the cycles DAQP fails
            # DAQP's stacked layout, written in place: M = [A; C] (self.A, where lock() writes the
            # lock rows, is a view on it), lo = [lbox'; 0; l'], hi = [ubox'; 0; u']
            self.stacked_M = np.zeros((ne + ni, nx))
            self.stacked_M[:ne] = self.A
            self.A = self.stacked_M[:ne]
            self.stacked_lo, self.stacked_hi = np.zeros(nx + ne + ni), np.zeros(nx + ne + ni)
        else:
            self.null_space = NullSpaceStep(solver, nx, ne, ni, scale)
            self.locked_backend = self.null_space.backend
        # banded form: variables z (nx), equalities A_eq z = 0, rows [C; locks], bounds on z
        self._Ab = np.zeros((self.n_eq_constraints, nx))
        self._bb = np.zeros(self.n_eq_constraints)
        self._Cb = np.zeros((self.n_in + n_lock, nx))
        self._lb = np.zeros(self.n_in + n_lock)
        self._ub = np.zeros(self.n_in + n_lock)
        self._lboxb = np.zeros(nx)
        self._uboxb = np.zeros(nx)
        self.banded_backend = None
        # GENERALIZED: the locked rows made orthonormal, which the banded form bounds (set by
        # orthonormal_lock_rows, each cycle before lock(); None: the rows as they are)
        self.band_rows: np.ndarray | None = None
        self.reference_x: np.ndarray | None = None  # every priority 0: the solution (bands())
        self._Q = np.zeros((n_lock, nx))
        # temporal damping per variable, in the solver's units (wrenches in the robot's weight)
        self.damping_w = 1.0 / np.square(scale)
        # temporal damping mu W ||x - x_prev||^2 (see set_temporal_damping); x_prev: this level's
        # solution of the previous cycle, which x holds while _prev_ok[0] (x is written by the
        # level's solves only; the compiled cycle's kernels read the flag too)
        self.temporal_damping = 0.0  # the controller sets its default
        # what the damping is relative to this cycle: the summed weights of the level's own tasks
        # (ramps left out), times its priority alpha under GENERALIZED (set by the cascade)
        self.damping_scale = 1.0
        self.prev_ok = np.zeros(1, dtype=np.int64)

    def set_temporal_damping(self, mu: float) -> None:
        """
        Pull this level's solution towards its previous cycle's: + mu W ||x - x_prev||^2.

        W: the summed weights of the level's own computing tasks (``damping_scale``, set each cycle
        by the cascade; under GENERALIZED a share of the upper levels' too, see
        ``PriorityLevels.damping_scale``), so that mu is a ratio that does not depend on how the
        level is weighted: with W ||x - x_prev||^2 against a cost of the same weight, the level's
        solution follows its optimum as a first-order filter of about mu cycles where nothing else
        binds.

        A lower level whose tasks conflict with the levels above sits on the bounds left to it, and
        hops between vertices of that set as bounds come and go (a velocity limit riding on and
        off): its accelerations jump by tens of rad/s^2 from one cycle to the next. The damping
        makes it move continuously; it acts in the null space of the locked rows only, so the
        levels above are untouched. 0 solves each cycle on its own. Wrenches are damped
        in units of the robot's weight (as the solver sees them). A level's first cycle (and the
        first after a failure, or after cycles where all its tasks were off) is damped towards the
        solution of the level above, so that a level switched on starts from what the robot
        already does.
        """
        mu = float(mu)
        if not (np.isfinite(mu) and mu >= 0.0):
            raise ValueError(f'temporal damping must be finite and >= 0, got {mu}')
        self.temporal_damping = mu
        if mu == 0.0:
            self.prev_ok[0] = 0

    def backends(self):
        return [self.locked_backend, self.banded_backend]

    def _make_backend(self):
        return None  # the level's own back-ends are made in __init__ (strict / banded forms)

    def orthonormal_lock_rows(self) -> np.ndarray:
        """
        Make ``band_rows`` this cycle's locked rows, orthonormal (:func:`orthonormalise_locks`).

        The rows of the GENERALIZED strategy's bands (see :mod:`.generalized`): each row of a
        task, less its part along the rows before it, made a unit row (zero where it depends on
        them). Call before :meth:`lock`; the strict form is unchanged.
        """
        k, Q = 0, self._Q
        for t in self.locked:
            m = t.rows()
            if t.get_effective_weight() > 0.0:
                np.multiply(t.E, t.selection[:, None], out=Q[k: k + m])
            else:
                Q[k: k + m] = 0.0
            k += m
        orthonormalise_locks(Q)
        self.band_rows = Q
        return Q

    def lock(self, x_above: np.ndarray, band: np.ndarray | None = None) -> None:
        """
        Keep the locked rows at their value at x_above.

        Exactly (band None or all zero: the strict form) or to +-band (the banded form, on the
        rows ``band_rows`` where they are set, else on the rows as they are).

        A locked task that is ramping in or out (activation factor rho in (0, 1)) is released
        progressively: its rows get the band  (1 - rho) / rho * (|s E x_above| + |s f| + 1)  (on
        orthonormal rows q: (1 - rho) / rho * (|q . x_above| + 1)),  0 when fully active and
        growing without bound as the task fades, so that switching a higher-level task off (or
        on) moves the levels below continuously instead of dropping (or imposing) a lock at once.
        """
        super().lock(x_above)
        self.x_ref[:] = x_above
        Q = self.band_rows
        k = 0
        for t in self.locked:
            m = t.rows()
            rho = t.get_ramp_value() if t.is_computing() else 0.0
            if 0.0 < rho < 1.0 and t.get_effective_weight() > 0.0:
                if band is None:
                    band = np.zeros(self.lock_rows())
                if Q is None:
                    lock_value = self.b[
                        self.n_eq_constraints + k: self.n_eq_constraints + k + m
                    ]  # s E x_above
                    scale = (np.abs(lock_value) + np.abs(t.selection * t.f) + 1.0) * (
                        t.selection > 0)
                else:
                    scale = np.abs(Q[k: k + m] @ x_above) + 1.0
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
        if self.band is not None and self.reference_x is not None:  # (GENERALIZED, alpha 0)
            np.copyto(self.x, self.reference_x)
            if self.temporal_damping > 0.0:
                self.prev_ok[0] = 1
            self.return_code = ReturnCode.SUCCESS
            return self.return_code
        mu = self.temporal_damping * self.damping_scale
        # the first cycle (or after a failure): towards the level above's solution, so that a
        # level starts from what the robot is already doing instead of jumping to its optimum
        prev = self.x if self.prev_ok[0] else self.x_ref
        if mu > 0.0:  # + mu ||(x - x_prev) / d||^2 (the solver's units), undone after the solve
            mw = mu * self.damping_w
            self._diag += mw
            self.g -= mw * prev
        try:
            if self.band is not None:
                code, dx = self._solve_banded()
            elif self.null_space is None:
                code, dx = self._solve_locked_stacked()
            else:
                code, dx = self._solve_locked()
        finally:
            if mu > 0.0:
                self._diag -= mw
                self.g += mw * prev
        if code is ReturnCode.SUCCESS:
            if np.isfinite(dx.sum()):
                np.add(self.x_ref, dx, out=self.x)
            else:
                code = ReturnCode.NON_FINITE_SOLUTION
        if self.temporal_damping > 0.0:  # after a failure, start again from the next solution
            self.prev_ok[0] = code is ReturnCode.SUCCESS
        self.return_code = code
        return code

    def _relaxed(self, lo, hi, value, out_lo, out_hi) -> None:
        # room left to the step z, less _ROOM_TOL: the level above meets its bounds only to its
        # solver's accuracy; a crumb of room left by rounding (on a joint resting on its bound)
        # let a posture level move far along a direction that barely touches that joint, and not
        # at all the next cycle (a torque step): less the tolerance, the room is 0 then and grows
        # continuously
        np.subtract(lo, value, out=out_lo)
        out_lo += _ROOM_TOL
        np.minimum(out_lo, 0.0, out=out_lo)
        np.subtract(hi, value, out=out_hi)
        out_hi -= _ROOM_TOL
        np.maximum(out_hi, 0.0, out=out_hi)

    def _solve_banded(self):
        nx, n_in, ne = self.layout.nx, self.n_in, self.n_eq_constraints
        if self.banded_backend is None:
            self.banded_backend = make_backend(
                self.solver_type, nx, ne, self._Cb.shape[0], scale=self.layout.variable_scale
            )
            self.banded_backend.deadline = self.locked_backend.deadline
            self.banded_backend.max_iterations = self.locked_backend.max_iterations
        self._Ab[:] = self.A[
            :ne
        ]  # x_ref satisfies the equalities: keep them as they are (A z = 0)
        g = self.H @ self.x_ref + self.g
        if n_in:
            self._Cb[:n_in] = self.C
            self._relaxed(self.l, self.u, self.C @ self.x_ref, self._lb[:n_in], self._ub[:n_in])
        self._Cb[n_in:] = self.A[ne:] if self.band_rows is None else self.band_rows
        np.negative(self.band, out=self._lb[n_in:])
        self._ub[n_in:] = self.band
        self._relaxed(self.lbox, self.ubox, self.x_ref, self._lboxb, self._uboxb)
        code = self.banded_backend.solve(
            self.H, g, self._Ab, self._bb, self._Cb, self._lb, self._ub, self._lboxb, self._uboxb
        )
        return code, (self.banded_backend.x if code is ReturnCode.SUCCESS else None)

    def _solve_locked(self):
        """Solve the strict form in a null-space basis (ProxQP, OSQP)."""
        n_in = self.n_in
        g = self.H @ self.x_ref + self.g
        if n_in:
            self._relaxed(self.l, self.u, self.C @ self.x_ref, self._lb[:n_in], self._ub[:n_in])
        self._relaxed(self.lbox, self.ubox, self.x_ref, self._lboxb, self._uboxb)
        return self.null_space.solve(
            self.H, g, self.A, self.C, self._lb[:n_in], self._ub[:n_in], self._lboxb, self._uboxb
        )

    def _solve_locked_stacked(self):
        """Solve the strict form in DAQP's layout: nothing copied but the inequality rows."""
        nx, ne, ni = self.layout.nx, self.n_eq, self.n_in
        lo, hi = self.stacked_lo, self.stacked_hi
        g = self.H @ self.x_ref + self.g
        if ni:
            self.stacked_M[ne:] = self.C
            self._relaxed(self.l, self.u, self.C @ self.x_ref, lo[nx + ne:], hi[nx + ne:])
        self._relaxed(self.lbox, self.ubox, self.x_ref, lo[:nx], hi[:nx])
        orthonormalise_locks(self.stacked_M[self.n_eq_constraints: ne])
        np.dot(self.A[self.n_eq_constraints:], self.x_ref, out=self.b[self.n_eq_constraints:])
        b = self.locked_backend
        code = b.solve_stacked(self.H, g, self.stacked_M, lo, hi)
        if code is not ReturnCode.SUCCESS:
            return self.solve_stacked_in_null_space(self.H, g)
        return code, b.x

    def solve_stacked_in_null_space(self, H, g):
        """
        Solve the strict form of DAQP's layout (the step's H and g) in a null-space basis.

        When DAQP failed on it. DAQP does not take a degenerate vertex: a bound that the locks
        already imply (a joint the levels above fix) and that sits at zero room makes it declare
        the problem infeasible (the Panda 3-level stack, elbow rows of rank 2, the fingers on
        their limits); in the null space of the locks that bound is an empty row. An SVD, only in
        the cycles DAQP fails. Returns (code, z or None).
        """
        nx, ne = self.layout.nx, self.n_eq
        if self._retry is None:
            self._retry = NullSpaceStep(
                self.solver_type, nx, ne, self.n_in, self.layout.variable_scale
            )
        self._retry.backend.deadline = self.locked_backend.deadline
        self._retry.backend.max_iterations = self.locked_backend.max_iterations
        lo, hi, M = self.stacked_lo, self.stacked_hi, self.stacked_M
        return self._retry.solve(
            H, g, M[:ne], M[ne:], lo[nx + ne:], hi[nx + ne:], lo[:nx], hi[:nx]
        )

    def lock_rows(self) -> int:
        return self.n_eq - self.n_eq_constraints
