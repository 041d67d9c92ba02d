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
DAQP back-end.

A dual active-set solver for small dense QPs (Arnström, Bemporad, Axehill, IEEE TAC 2022).

Why it is the default: on the controller's QPs (bench/bench_solvers.py, the Panda, quadruped and
Talos scenarios of bench/peer/scenarios.py in closed loop) a warm-started cycle takes one
active-set iteration and the solve is faster than ProxQP's on each scenario and several times
faster than OSQP's; it returns the exact solution of its final active set (no
tolerance-driven drift between solvers), and, being a dual method, finds an infeasible problem
quickly instead of iterating to a limit.

Layout: DAQP takes one constraint matrix whose first rows may be plain variable bounds; here the
bounds are the variables' box, then the equality rows A x = b (sense 5: always active), then the
inequality rows l <= C x <= u. The active set of the last solve is kept by the workspace: the next
cycle starts from it.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .base import QPBackend, ReturnCode
from ...utils.optional_import import optional_import

_EQUALITY = 5
# DAQP's exit flags (1 optimal, 2 optimal with soft constraints, -1 infeasible, -2 cycling, -3
# unbounded, -4 iteration limit, -5 non-convex, -6 over-determined initial active set)
_FLAGS = {
    1: ReturnCode.SUCCESS,
    2: ReturnCode.SUCCESS,
    -1: ReturnCode.PRIMAL_INFEASIBLE,
    -3: ReturnCode.DUAL_INFEASIBLE,
    -4: ReturnCode.MAX_ITERATIONS,
    -5: ReturnCode.SOLVER_ERROR,
}


class DAQPBackend(QPBackend):
    name = 'daqp'

    def __init__(self, nx: int, n_eq: int, n_in: int):
        # not packaged for rosdep: a missing package is an error naming the pip line
        self._daqp = optional_import('daqp', "solver 'daqp'", 'or solver: proxqp / osqp')
        super().__init__(nx, n_eq, n_in)
        m = n_eq + n_in
        self._M = np.zeros((m, nx))
        self._bu = np.zeros(nx + m)
        self._bl = np.zeros(nx + m)
        self._sense = np.zeros(nx + m, dtype=np.int32)
        self._sense[nx: nx + n_eq] = _EQUALITY
        self._model = None

    def reset(self) -> None:
        self._model = None

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        n, ne = self.nx, self.n_eq
        M, bu, bl = self._M, self._bu, self._bl
        if ne:
            M[:ne] = A
            bu[n: n + ne] = b
            bl[n: n + ne] = b
        if self.n_in:
            M[ne:] = C
            bu[n + ne:] = u
            bl[n + ne:] = lc
        bu[:n] = ubox
        bl[:n] = lbox
        return self.solve_stacked(H, g, M, bl, bu)

    def solve_stacked(self, H, g, M, lo, hi) -> ReturnCode:
        """
        Solve the problem already in DAQP's layout.

        M = [A; C], lo = [lbox; b; l], hi = [ubox; b; u] (infinite entries are DAQP's 'no bound').
        """
        warm = self._model is not None
        cap = self.iteration_cap()
        code = self._solve_once(H, g, M, lo, hi, cap)
        if code is not ReturnCode.SUCCESS and warm and self.iterations < cap:
            code = self._solve_once(
                H, g, M, lo, hi, cap - self.iterations
            )  # once more, empty active set
        return code

    def _solve_once(self, H, g, M, lo, hi, cap: int) -> ReturnCode:
        try:
            if self._model is None:
                model = self._daqp.Model()
                flag, _ = model.setup(H, g, M, hi, lo, self._sense)
                if flag < 0:  # e.g. crossed bounds or a Hessian that is not positive definite
                    self.iterations = 0
                    return _FLAGS.get(int(flag), ReturnCode.SOLVER_ERROR)
                self._model = model
                self._cap = None
            else:
                flag = self._model.update(H=H, f=g, A=M, bupper=hi, blower=lo)
                if flag < 0:  # e.g. crossed bounds, found before any solve
                    self._model = None
                    self.iterations = 0
                    return _FLAGS.get(int(flag), ReturnCode.SOLVER_ERROR)
            if cap != self._cap:
                self._model.settings = {'iter_limit': int(cap)}
                self._cap = cap
            t0 = time.perf_counter()
            x, _, flag, info = self._model.solve()
        except Exception:  # noqa: BLE001 - DAQP raises on inconsistent data: the caller reports it
            self._model = None
            return ReturnCode.SOLVER_ERROR
        self.iterations = int(info['iterations'])
        self.record(time.perf_counter() - t0, self.iterations)
        code = _FLAGS.get(int(flag), ReturnCode.NOT_SOLVED)
        if code is ReturnCode.SUCCESS and not math.isfinite(x.sum()):
            # a warm active set holding a row whose bound just became infinite (a constraint
            # switched off)
            code = ReturnCode.NON_FINITE_SOLUTION
        if code is ReturnCode.SUCCESS:
            self.x = x
        else:
            self._model = None  # a failed solve leaves a useless active set: start cold next time
        return code
