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
OSQP back-end with a fixed sparsity pattern (dense blocks stored explicitly) and warm starts.

OSQP's constraint matrix is [I; A; C] with bounds [lbox; b; l] .. [ubox; b; u]; its cost matrix is
the upper triangle of H. Both patterns are built once; every cycle only their values are updated.
Polishing is on, so a solved problem is returned at active-set accuracy (it agrees with ProxQP to
~1e-9).
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.sparse as sp

from .base import QPBackend, ReturnCode
from ...utils.optional_import import optional_import

_INF = 1e30


class _Discard:
    """
    Swallows text.

    OSQP 1.x prints 'Polishing not needed ...' through Python's stdout even when verbose is off;
    the control loop must not write to stdout every cycle.
    """

    def write(self, text):
        return len(text)

    def flush(self):
        pass


_DISCARD = _Discard()


class OSQPBackend(QPBackend):
    name = 'osqp'

    default_max_iterations = 20000
    min_iterations = (
        200  # ADMM: a warm-started cycle takes tens of iterations, termination checked every 25
    )

    def __init__(self, nx: int, n_eq: int, n_in: int, eps: float = 1e-7):
        super().__init__(nx, n_eq, n_in)
        self.eps = eps
        n = nx
        self._triu = np.triu_indices(n)
        # CSC of the upper triangle, column by column: rows 0..j of column j
        cols_order = np.lexsort((self._triu[0], self._triu[1]))
        self._p_rows = self._triu[0][cols_order]
        self._p_cols = self._triu[1][cols_order]
        p_indptr = np.concatenate(([0], np.cumsum(np.arange(1, n + 1))))
        self._P_pattern = sp.csc_matrix(
            (np.ones(self._p_rows.size), self._p_rows, p_indptr), shape=(n, n)
        )
        m = n + n_eq + n_in
        rows = []
        for j in range(n):
            rows.append(np.concatenate(([j], n + np.arange(n_eq + n_in))))
        a_indices = np.concatenate(rows)
        a_indptr = np.arange(n + 1) * (1 + n_eq + n_in)
        self._A_pattern = sp.csc_matrix(
            (np.ones(a_indices.size), a_indices, a_indptr), shape=(m, n)
        )
        self._stack = np.zeros((1 + n_eq + n_in, n))
        self._stack[0] = 1.0
        self._l = np.zeros(m)
        self._u = np.zeros(m)
        self._solver = None

    def reset(self) -> None:
        self._solver = None

    def _values(self, H, A, C):
        Px = H[self._p_rows, self._p_cols]
        st = self._stack
        if self.n_eq:
            st[1: 1 + self.n_eq] = A
        if self.n_in:
            st[1 + self.n_eq:] = C
        return Px, st.T.ravel()

    def _bounds(self, b, lc, u, lbox, ubox):
        n, ne = self.nx, self.n_eq
        lo, hi = self._l, self._u
        lo[:n], hi[:n] = lbox, ubox
        if ne:
            lo[n: n + ne] = b
            hi[n: n + ne] = b
        if self.n_in:
            lo[n + ne:], hi[n + ne:] = lc, u
        np.clip(lo, -_INF, _INF, out=lo)
        np.clip(hi, -_INF, _INF, out=hi)
        return lo, hi

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        Px, Ax = self._values(H, A, C)
        lo, hi = self._bounds(b, lc, u, lbox, ubox)
        warm = self._solver is not None
        cap = self.iteration_cap()
        code = self._solve_once(Px, Ax, g, lo, hi, cap)
        if code is not ReturnCode.SUCCESS and warm and self.iterations < cap:
            code = self._solve_once(Px, Ax, g, lo, hi, cap - self.iterations)  # once more, cold
        return code

    def _solve_once(self, Px, Ax, g, lo, hi, cap: int) -> ReturnCode:
        try:
            if self._solver is None:
                P = self._P_pattern.copy()
                P.data[:] = Px
                Am = self._A_pattern.copy()
                Am.data[:] = Ax
                s = optional_import(
                    'osqp', "solver 'osqp'", 'or solver: daqp / proxqp'
                ).OSQP()
                s.setup(
                    P,
                    g,
                    Am,
                    lo,
                    hi,
                    verbose=False,
                    eps_abs=self.eps,
                    eps_rel=self.eps,
                    polishing=True,
                    max_iter=int(cap),
                    warm_starting=True,
                    adaptive_rho=True,
                )
                self._solver = s
            else:
                self._solver.update(q=g, l=lo, u=hi, Px=Px, Ax=Ax)
                self._solver.update_settings(max_iter=int(cap))
            saved, sys.stdout = sys.stdout, _DISCARD
            t0 = time.perf_counter()
            try:
                res = self._solver.solve(raise_error=False)
            finally:
                sys.stdout = saved
        except Exception:
            self._solver = None
            return ReturnCode.SOLVER_ERROR
        self.iterations = res.info.iter
        self.record(time.perf_counter() - t0, self.iterations)
        status = res.info.status
        # "solved inaccurate": within 10x the tolerances (1e-6 here) when the iteration cap came
        # first; an ADMM solution that good is a usable command, and the cap is what bounds the
        # cycle
        if status in ('solved', 'solved inaccurate'):
            self.x = res.x
            return ReturnCode.SUCCESS
        self._solver = None
        if 'infeasible' in status and 'dual' in status:
            return ReturnCode.DUAL_INFEASIBLE
        if 'infeasible' in status:
            return ReturnCode.PRIMAL_INFEASIBLE
        if 'maximum iterations' in status:
            return ReturnCode.MAX_ITERATIONS
        return ReturnCode.NOT_SOLVED
