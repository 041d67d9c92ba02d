"""One weighted QP level: tasks summed with their (ramped) weights, all constraints applied.

In a strict hierarchy a level also receives the tasks of every level above it as *locked* tasks: rows
diag(s) E x = diag(s) E x*, with x* the solution of the level just above (see :mod:`.lower_level_problem`,
which solves such a level relative to x*; here the rows only describe the problem, e.g. for a KKT solve).

Sizes, row offsets and the solver's sparsity pattern are fixed when the problem is created (at
configuration time); :meth:`build` only writes values into preallocated arrays.
"""
from __future__ import annotations

import numpy as np

from ..optim.solvers import ReturnCode, make_backend
from ..utils.logger import get_logger

_LOG = get_logger("optim")


class WeightedProblem:
    def __init__(self, layout, tasks, constraints, solver, level: int = 0, locked_tasks=()):
        self.layout = layout
        self.level = level
        self.tasks = list(tasks)
        self.locked = list(locked_tasks)
        self.solver_type = solver
        nx = layout.nx
        # contacts own wrench variables, bounded through the variable bounds (zero while switched off)
        self.contacts = [c for c in constraints if getattr(c, "is_contact", False)]
        # constraints without rows for this robot (e.g. the dynamics' floating-base rows on a fixed base)
        # cost nothing at run time
        constraints = [c for c in constraints if c.rows() > 0]
        self.eq = [c for c in constraints if c.kind == "equality"]
        self.ineq = [c for c in constraints if c.kind == "inequality"]
        self.soft_box = [c for c in constraints if c.kind == "box" and not c.hard]
        self.hard_box = [c for c in constraints if c.kind == "box" and c.hard]
        self._eq_rows = self._offsets(self.eq)
        self._in_rows = self._offsets(self.ineq)
        self.n_eq_constraints = sum(c.rows() for c in self.eq)
        self._lock_rows = [slice(self.n_eq_constraints + r.start, self.n_eq_constraints + r.stop)
                           for r in self._offsets(self.locked)]
        self.n_eq = self.n_eq_constraints + sum(t.rows() for t in self.locked)
        self.n_in = sum(c.rows() for c in self.ineq)
        self.H = np.zeros((nx, nx))
        self.g = np.zeros(nx)
        self.A = np.zeros((self.n_eq, nx))
        self.b = np.zeros(self.n_eq)
        self.C = np.zeros((self.n_in, nx))
        self.l = np.full(self.n_in, -np.inf)
        self.u = np.full(self.n_in, np.inf)
        self.lbox = np.full(nx, -np.inf)
        self.ubox = np.full(nx, np.inf)
        self._lo = np.empty(layout.ndof)
        self._hi = np.empty(layout.ndof)
        self.backend = self._make_backend()
        self.x = np.zeros(nx)
        self.return_code = ReturnCode.NOT_SOLVED
        self.box_conflicts = 0

    def _make_backend(self):
        return make_backend(self.solver_type, self.layout.nx, self.n_eq, self.n_in)

    @staticmethod
    def _offsets(cons):
        out, k = [], 0
        for c in cons:
            m = c.rows()
            out.append(slice(k, k + m))
            k += m
        return out

    def lock(self, x_above: np.ndarray) -> None:
        """Keep the residuals the higher levels reached at x_above (their tasks' E, f of this cycle)."""
        for t, rows in zip(self.locked, self._lock_rows):
            if t.get_effective_weight() > 0.0:
                np.multiply(t.E, t.selection[:, None], out=self.A[rows])
                np.dot(self.A[rows], x_above, out=self.b[rows])
            else:
                self.A[rows] = 0.0
                self.b[rows] = 0.0

    # -------------------------------------------------------------- build
    def build(self) -> None:
        H, g = self.H, self.g
        H.fill(0.0)
        g.fill(0.0)
        diag = H.reshape(-1)[:: H.shape[0] + 1]  # view on the diagonal
        for t in self.tasks:
            w = t.get_effective_weight()
            if w <= 0.0:
                continue
            if t.identity_E:  # E = I: no product needed
                ws = w * t.selection
                diag += ws
                g -= ws * t.f
                continue
            Ews = t.E.T * (w * t.selection)
            H += Ews @ t.E
            g -= Ews @ t.f
        for c, rows in zip(self.eq, self._eq_rows):
            if c.is_computing():
                self.A[rows] = c.C
                self.b[rows] = c.lb
            else:
                self.A[rows] = 0.0
                self.b[rows] = 0.0
        for c, rows in zip(self.ineq, self._in_rows):
            if c.is_computing():
                self.C[rows] = c.C
                self.l[rows] = c.lb
                self.u[rows] = c.ub
            else:
                self.l[rows] = -np.inf
                self.u[rows] = np.inf
        self._build_box()
        for c in self.contacts:
            ws = c.wrench_slice()
            if c.is_computing():
                self.lbox[ws] = c.wrench_lower
                self.ubox[ws] = c.wrench_upper
            else:
                self.lbox[ws] = 0.0
                self.ubox[ws] = 0.0

    def _build_box(self) -> None:
        if not self.soft_box and not self.hard_box:
            return
        lo, hi = self._lo, self._hi
        lo.fill(-np.inf)
        hi.fill(np.inf)
        for c in self.soft_box:
            if c.is_computing():
                np.maximum(lo, c.lb, out=lo)
                np.minimum(hi, c.ub, out=hi)
        bad = lo > hi
        if bad.any():
            # position and velocity predictions disagree (e.g. fast motion near a limit): keep a finite,
            # feasible compromise rather than an empty set
            mid = 0.5 * (lo[bad] + hi[bad])
            lo[bad] = mid
            hi[bad] = mid
            self.box_conflicts += 1
        for c in self.hard_box:
            if c.is_computing():
                np.clip(lo, c.lb, c.ub, out=lo)
                np.clip(hi, c.lb, c.ub, out=hi)
        js = self.layout.joint_acc
        self.lbox[js] = lo
        self.ubox[js] = hi

    # -------------------------------------------------------------- solve
    def solve(self) -> ReturnCode:
        # states, targets, gains and limits are validated where they enter; the matrices built from them
        # are finite unless a task computed garbage, which shows in the cost
        if not np.isfinite(self.H.sum() + self.g.sum()):
            self.return_code = ReturnCode.NON_FINITE_PROBLEM
            return self.return_code
        code = self.backend.solve(self.H, self.g, self.A, self.b, self.C, self.l, self.u, self.lbox, self.ubox)
        if code is ReturnCode.SUCCESS:
            x = self.backend.x
            if not np.isfinite(x.sum()):
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
            v = max(v, float(np.max(self.l - y, initial=0.0)), float(np.max(y - self.u, initial=0.0)))
        v = max(v, float(np.max(self.lbox - x, initial=0.0)), float(np.max(x - self.ubox, initial=0.0)))
        return v
