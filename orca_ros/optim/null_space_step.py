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
The step of a strict lower level in a null-space basis, for solvers that need independent rows.

A strict level holds the rows of the levels above and the constraint equalities, A z = 0, for its
step z = x - x_ref. DAQP takes them as equality rows and its active set leaves out the dependent
ones (see :mod:`.lower_level_problem`). ProxQP and OSQP do not converge on dependent equality rows
(on the 3-level arm stack both stop at their iteration limits, OSQP often); for them the
step is z = D N y with N an orthonormal basis of the null space of A D from an SVD (rank decided at
1e-9 relative), D the variables' scale, so that the locks cost no row at all. Inequalities and
bounds become rows [C D N; D N] with the relaxed bounds, normalised; a row that the null space does
not reach (a joint the levels above fix entirely) is rounding noise (~1e-16) and is left out:
normalised, its sign would cut the step's space in half at random.
"""

from __future__ import annotations

import numpy as np

from .solvers import make_backend, ReturnCode

_RANK_TOL = 1e-9  # singular values below this (relative to the largest, at least 1) count as zero
_EMPTY_ROW = 1e-10  # projected rows shorter than this are empty (unit rows have norm ~1)


class NullSpaceStep:
    def __init__(self, solver, nx: int, n_eq: int, n_in: int, scale: np.ndarray):
        self.nx, self.n_in = nx, n_in
        self._N = np.zeros((nx, nx))
        self._Hs = np.zeros((nx, nx))
        self._gs = np.zeros(nx)
        self._Cs = np.zeros((n_in + nx, nx))
        self._ls = np.zeros(n_in + nx)
        self._us = np.zeros(n_in + nx)
        self._free = np.full(nx, np.inf)
        self.backend = make_backend(solver, nx, 0, n_in + nx, box=False)
        self._scale = None if np.all(scale == 1.0) else scale
        self._As = np.zeros((n_eq, nx))
        self.null_space_dimension = nx

    def solve(self, H, g, A, C, lo, hi, lbox, ubox):
        """
        Minimise 1/2 z^T H z + g^T z with A z = 0, lo <= C z <= hi, lbox <= z <= ubox.

        The bounds contain z = 0 (relaxed by the caller). Returns (code, z or None).
        """
        nx, n_in = self.nx, self.n_in
        N = self._N
        N.fill(0.0)
        d = self._scale
        if A.shape[0]:
            As = A if d is None else np.multiply(A, d, out=self._As)
            _, s, vt = np.linalg.svd(As, full_matrices=True)
            r = int(np.count_nonzero(s > _RANK_TOL * max(1.0, s[0] if s.size else 0.0)))
        else:
            vt, r = np.eye(nx), 0
        k = nx - r
        self.null_space_dimension = k
        if k == 0:  # the levels above use every degree of freedom: nothing left to optimise
            return ReturnCode.SUCCESS, np.zeros(nx)
        N[:, :k] = vt[r:].T
        if d is not None:
            N *= d[:, None]
        np.dot(N.T, H @ N, out=self._Hs)
        self._Hs[range(k, nx), range(k, nx)] = 1.0  # padding variables: zero columns, pinned at 0
        np.dot(N.T, g, out=self._gs)
        if n_in:
            np.dot(C, N, out=self._Cs[:n_in])
            self._ls[:n_in], self._us[:n_in] = lo, hi
        self._Cs[n_in:] = N
        self._ls[n_in:], self._us[n_in:] = lbox, ubox
        # rows of very different scales (torques, accelerations) slow the solvers down on these
        # often degenerate problems: normalise them; rows the null space does not reach are empty
        norms = np.linalg.norm(self._Cs, axis=1)
        empty = norms < _EMPTY_ROW
        norms[empty] = 1.0
        self._Cs /= norms[:, None]
        self._ls /= norms
        self._us /= norms
        if empty.any():
            self._Cs[empty] = 0.0
            self._ls[empty] = -np.inf
            self._us[empty] = np.inf
        code = self.backend.solve(
            self._Hs, self._gs, None, None, self._Cs, self._ls, self._us, -self._free, self._free
        )
        if code is not ReturnCode.SUCCESS:
            return code, None
        return code, N @ self.backend.x
