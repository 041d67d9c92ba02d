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
Variable scaling at the solver's door: the back-end solves for x~ = x / d.

The controller's variables have different units: accelerations (~1-100 rad/s^2) and contact
wrenches (~ the robot's weight, up to 10^3 N). A regularisation that is negligible in physical
units (1e-4 ||w / (m g)||^2) then puts ~1e-10 on the Hessian's diagonal next to ~1 for the
accelerations, and iterative solvers stop on a wrench distribution far from the optimum (one sole
left unloaded). With x = D x~, D = diag(d), the problem handed to the solver is

    min 1/2 x~^T (D H D) x~ + (D g)^T x~
    s.t.  A D x~ = b,   l <= C D x~ <= u,   lbox / d <= x~ <= ubox / d

which has the same solution (x = D x~) and the conditioning of the physical problem. d comes from
the :class:`~orca_ros.optim.problem_layout.ProblemLayout` (1 for accelerations, the robot's
weight for wrenches).
"""

from __future__ import annotations

import numpy as np

from .base import ReturnCode


class ScaledBackend:
    """Wraps a back-end; the same interface (``solve``, ``solve_stacked``, ``x``, budget)."""

    def __init__(self, inner, scale: np.ndarray):
        self.inner = inner
        d = np.asarray(scale, dtype=float).copy()
        self.d = d
        self._inv = 1.0 / d
        self._dd = np.outer(d, d)
        nx, ne, ni = inner.nx, inner.n_eq, inner.n_in
        self.nx, self.n_eq, self.n_in = nx, ne, ni
        self._H = np.zeros((nx, nx))
        self._g = np.zeros(nx)
        self._A = np.zeros((ne, nx))
        self._C = np.zeros((ni, nx))
        self._M = np.zeros((ne + ni, nx))
        self._lbox, self._ubox = np.zeros(nx), np.zeros(nx)
        self._lo, self._hi = np.zeros(nx + ne + ni), np.zeros(nx + ne + ni)
        self.x = np.zeros(nx)
        if hasattr(inner, 'solve_stacked'):
            self.solve_stacked = self._solve_stacked

    # budget and statistics live in the wrapped back-end
    name = property(lambda self: self.inner.name)
    iterations = property(lambda self: self.inner.iterations)
    default_max_iterations = property(lambda self: self.inner.default_max_iterations)

    @property
    def deadline(self):
        return self.inner.deadline

    @deadline.setter
    def deadline(self, value):
        self.inner.deadline = value

    @property
    def max_iterations(self):
        return self.inner.max_iterations

    @max_iterations.setter
    def max_iterations(self, value):
        self.inner.max_iterations = value

    def __getattr__(self, name):
        return getattr(self.inner, name)  # anything else: the wrapped back-end's

    def reset(self) -> None:
        self.inner.reset()

    def _objective(self, H, g):
        np.multiply(H, self._dd, out=self._H)
        np.multiply(g, self.d, out=self._g)
        return self._H, self._g

    def _result(self, code: ReturnCode) -> ReturnCode:
        if code is ReturnCode.SUCCESS:
            np.multiply(self.inner.x, self.d, out=self.x)
        return code

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        Hs, gs = self._objective(H, g)
        As = np.multiply(A, self.d, out=self._A) if A is not None and self.n_eq else A
        Cs = np.multiply(C, self.d, out=self._C) if C is not None and self.n_in else C
        np.multiply(lbox, self._inv, out=self._lbox)
        np.multiply(ubox, self._inv, out=self._ubox)
        return self._result(
            self.inner.solve(Hs, gs, As, b, Cs, lc, u, self._lbox, self._ubox)
        )

    def _solve_stacked(self, H, g, M, lo, hi) -> ReturnCode:
        """Solve in the stacked layout M = [A; C], lo = [lbox; b; l], hi = [ubox; b; u] (DAQP)."""
        Hs, gs = self._objective(H, g)
        n = self.nx
        np.multiply(M, self.d, out=self._M)
        np.multiply(lo[:n], self._inv, out=self._lo[:n])
        np.multiply(hi[:n], self._inv, out=self._hi[:n])
        self._lo[n:] = lo[n:]
        self._hi[n:] = hi[n:]
        return self._result(self.inner.solve_stacked(Hs, gs, self._M, self._lo, self._hi))
