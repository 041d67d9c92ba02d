"""Dense ProxQP back-end (proxsuite) with native box constraints and warm starts."""
from __future__ import annotations

import proxsuite

from .base import QPBackend, ReturnCode

_dense = proxsuite.proxqp.dense
_STATUS = proxsuite.proxqp.QPSolverOutput


class ProxQPBackend(QPBackend):
    name = "proxqp"

    def __init__(self, nx: int, n_eq: int, n_in: int, eps_abs: float = 1e-9, max_iter: int = 1000):
        super().__init__(nx, n_eq, n_in)
        self.eps_abs = eps_abs
        self.max_iter = max_iter
        self._make()

    def _make(self) -> None:
        qp = _dense.QP(self.nx, self.n_eq, self.n_in, True)
        st = qp.settings
        st.eps_abs = self.eps_abs
        st.eps_rel = 0.0
        st.max_iter = self.max_iter
        st.verbose = False
        st.compute_timings = False
        self._qp = qp
        self._initialized = False

    def reset(self) -> None:
        self._make()

    def solve(self, H, g, A, b, C, l, u, lbox, ubox) -> ReturnCode:
        qp = self._qp
        if self.n_eq == 0:
            A = b = None
        if self.n_in == 0:
            C = l = u = None
        try:
            if not self._initialized:
                qp.init(H, g, A, b, C, l, u, lbox, ubox)
                qp.solve()
                # warm starting needs a previous result: switching it on before the first solve crashes
                qp.settings.initial_guess = proxsuite.proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
                self._initialized = True
            else:
                qp.update(H, g, A, b, C, l, u, lbox, ubox)
                qp.solve()
        except Exception:  # proxsuite raises on inconsistent data; caller reports
            self._make()
            return ReturnCode.SOLVER_ERROR
        res = qp.results
        self.iterations = res.info.iter
        status = res.info.status
        if status == _STATUS.PROXQP_SOLVED:
            self.x = res.x
            return ReturnCode.SUCCESS
        # a failed solve leaves a poor warm start: start cold next time
        self._make()
        if status == _STATUS.PROXQP_MAX_ITER_REACHED:
            return ReturnCode.MAX_ITERATIONS
        if status == _STATUS.PROXQP_PRIMAL_INFEASIBLE:
            return ReturnCode.PRIMAL_INFEASIBLE
        if status == _STATUS.PROXQP_DUAL_INFEASIBLE:
            return ReturnCode.DUAL_INFEASIBLE
        return ReturnCode.NOT_SOLVED
