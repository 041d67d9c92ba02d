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
"""Dense ProxQP back-end (proxsuite) with native box constraints and warm starts."""

from __future__ import annotations

import time

from .base import QPBackend, ReturnCode
from ...utils.optional_import import optional_import

_MAX_INNER = 50


class ProxQPBackend(QPBackend):
    name = 'proxqp'
    # outer iterations: a warm-started feasible cycle takes one or two; on an infeasible
    # problem of a quadruped's size one may cost a good part of a period, so the floor is low
    min_iterations = 4

    def __init__(self, nx: int, n_eq: int, n_in: int, eps_abs: float = 1e-9, box: bool = True):
        # ros-jazzy-proxsuite (rosdep key proxsuite) or pip
        self._proxqp = optional_import(
            'proxsuite', "solver 'proxqp'", 'or solver: daqp / osqp'
        ).proxqp
        super().__init__(nx, n_eq, n_in)
        # without: lbox/ubox are ignored (infinite box rows mislead ProxQP's infeasibility test)
        self.box = box
        self.eps_abs = eps_abs
        self._make()

    def _make(self) -> None:
        qp = self._proxqp.dense.QP(self.nx, self.n_eq, self.n_in, self.box)
        st = qp.settings
        st.eps_abs = self.eps_abs
        st.eps_rel = 0.0
        st.max_iter = self.max_iterations
        # max_iter bounds the outer (proximal) iterations; each runs inner Newton iterations, 1500
        # by default: bounded too, so that one outer iteration cannot take a whole control period
        st.max_iter_in = _MAX_INNER
        # the default infeasibility thresholds (1e-4) declare feasible control QPs with active
        # torque limits infeasible within a few iterations; true infeasibility is still
        # detected at these
        st.eps_primal_inf = 1e-10
        st.eps_dual_inf = 1e-10
        # small primal and dual residuals alone let ProxQP stop at a point that is not optimal:
        # on Talos's scaled QP (a nearly unloaded sole, a degenerate wrench block) visibly off
        # DAQP's exact solution, in some processes and not others. With the duality gap checked
        # too, within the test's 1e-6 in every process (test_talos_balance.py)
        st.check_duality_gap = True
        st.eps_duality_gap_abs = min(self.eps_abs, 1e-9)
        st.eps_duality_gap_rel = 0.0
        st.verbose = False
        st.compute_timings = False
        self._qp = qp
        self._initialized = False

    def reset(self) -> None:
        self._make()

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        if self.n_eq == 0:
            A = b = None
        if self.n_in == 0:
            C = lc = u = None
        if not self.box:
            lbox = ubox = None
        warm = self._initialized
        cap = self.iteration_cap()
        code = self._solve_once(H, g, A, b, C, lc, u, lbox, ubox, cap)
        if code is not ReturnCode.SUCCESS and warm and self.iterations < cap:
            # a warm start from a different problem (limits or targets that moved) can make ProxQP
            # declare a feasible problem infeasible within a few iterations (measured): retry once
            # from a cold start
            code = self._solve_once(H, g, A, b, C, lc, u, lbox, ubox, cap - self.iterations)
        return code

    def _solve_once(self, H, g, A, b, C, lc, u, lbox, ubox, cap: int) -> ReturnCode:
        qp = self._qp
        qp.settings.max_iter = int(cap)
        try:
            if not self._initialized:
                if self.box:
                    qp.init(H, g, A, b, C, lc, u, lbox, ubox)
                else:
                    qp.init(H, g, A, b, C, lc, u)
                t0 = time.perf_counter()
                qp.solve()
                # warm starting needs a previous result: switching it on before the first solve
                # crashes
                qp.settings.initial_guess = (
                    self._proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
                )
                self._initialized = True
            else:
                if self.box:
                    qp.update(H, g, A, b, C, lc, u, lbox, ubox)
                else:
                    qp.update(H, g, A, b, C, lc, u)
                t0 = time.perf_counter()
                qp.solve()
        except Exception:  # proxsuite raises on inconsistent data; caller reports
            self._make()
            return ReturnCode.SOLVER_ERROR
        res = qp.results
        self.iterations = res.info.iter_ext  # the unit of max_iter (outer iterations)
        self.record(time.perf_counter() - t0, self.iterations)
        status = res.info.status
        if status == self._proxqp.QPSolverOutput.PROXQP_SOLVED:
            self.x = res.x
            return ReturnCode.SUCCESS
        # a failed solve leaves a poor warm start: start cold next time
        self._make()
        if status == self._proxqp.QPSolverOutput.PROXQP_MAX_ITER_REACHED:
            return ReturnCode.MAX_ITERATIONS
        if status == self._proxqp.QPSolverOutput.PROXQP_PRIMAL_INFEASIBLE:
            return ReturnCode.PRIMAL_INFEASIBLE
        if status == self._proxqp.QPSolverOutput.PROXQP_DUAL_INFEASIBLE:
            return ReturnCode.DUAL_INFEASIBLE
        return ReturnCode.NOT_SOLVED
