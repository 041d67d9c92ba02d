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
The controller's captured QPs and the solvers that the benchmarks time on them (project venv only).

:func:`snapshot` keeps, after a controller's cycle, the state (q, v) and its level-0 QP as the
solver receives it: already in solver units (x~ = x / d, the controller's variable scaling, see
orca_ros/optim/solvers/scaled_backend.py) and in DAQP's stacked layout (M = [A; C],
lo = [lbox; b; l], hi = [ubox; b; u]), plus the controller's own solution.

:class:`Solver` solves such a QP, warm-started from the previous one: DAQP, ProxQP and OSQP through
the controller's own back-ends (``make_backend``: the settings and tolerances the controller uses
for a problem of that scaling, no time budget), PIQP (an interior-point solver the controller does
not ship; no warm start) directly with eps_abs 1e-9. Scaling, stacking and copying happen at
capture time: a solve is timed on ready arrays, as the least a controller on this stack spends.
"""

from __future__ import annotations

import numpy as np

SOLVERS = ('daqp', 'proxqp', 'osqp', 'piqp')


class Captured:
    """One cycle: state, QP in solver units (stacked and split views), controller's solution."""

    __slots__ = ('q', 'v', 'H', 'g', 'M', 'lo', 'hi', 'split', 'x_ctrl')

    def __init__(self, q, v, H, g, M, lo, hi, nx, ne, x_ctrl):
        self.q, self.v = q, v
        self.H, self.g, self.M, self.lo, self.hi = H, g, M, lo, hi
        # (H, g, A, b, C, l, u, lbox, ubox): views on the stacked arrays
        self.split = (
            H, g, M[:ne], lo[nx: nx + ne], M[ne:], lo[nx + ne:], hi[nx + ne:], lo[:nx], hi[:nx]
        )
        self.x_ctrl = x_ctrl


def to_solver_units(H, g, M, lo, hi, d):
    """Return the problem in x~ = x / d (what the controller's ScaledBackend hands its solver)."""
    nx = H.shape[0]
    lo, hi = lo.copy(), hi.copy()
    lo[:nx] /= d
    hi[:nx] /= d
    return H * np.outer(d, d), g * d, M * d, lo, hi


def snapshot(controller, robot) -> Captured:
    """
    Keep the state and level-0 QP of the controller's last cycle (solver units) and its solution.

    The level must be a single weighted level in the stacked layout (the benchmark scenarios are).
    """
    p = controller.get_problem_at_level(0)
    lay = p.layout
    d = np.asarray(lay.variable_scale, float)
    H, g, M, lo, hi = to_solver_units(p.H, p.g, p.plan.M, p.plan.lo, p.plan.hi, d)
    return Captured(
        robot.buffers.q_pin.copy(),
        robot.buffers.v_pin.copy(),
        H,
        g,
        M,
        lo,
        hi,
        lay.nx,
        p.n_eq,
        p.x.copy(),
    )


class Solver:
    """A warm-started solver of captured QPs of fixed sizes; ``solve(c)`` -> success, ``x``."""

    def __init__(self, name: str, nx: int, ne: int, ni: int, scale):
        self.name = name
        self.nx, self.ne, self.ni = nx, ne, ni
        self.d = np.asarray(scale, float)
        self.iterations = 0
        if name == 'piqp':
            import piqp

            self._piqp = piqp
            self._s = None
            self.solve = self._solve_piqp
            return
        from orca_ros.optim.solvers import make_backend, QPSolver, ScaledBackend

        b = make_backend(QPSolver.from_string(name), nx, ne, ni, scale=self.d)
        # the controller's back-end for this scaling (its tolerances); its wrapped solver takes the
        # problem already in solver units
        self._b = b.inner if isinstance(b, ScaledBackend) else b
        self._b.deadline = None
        self.solve = (
            self._solve_stacked if hasattr(self._b, 'solve_stacked') else self._solve_split
        )

    @property
    def x(self):
        return self._x if self.name == 'piqp' else self._b.x

    def x_physical(self):
        return self.d * self.x

    def _solve_stacked(self, c) -> bool:
        ok = self._b.solve_stacked(c.H, c.g, c.M, c.lo, c.hi).value == 'success'
        self.iterations = self._b.iterations
        return ok

    def _solve_split(self, c) -> bool:
        ok = self._b.solve(*c.split).value == 'success'
        self.iterations = self._b.iterations
        return ok

    def _solve_piqp(self, c) -> bool:
        H, g, A, b, C, lc, u, lbox, ubox = c.split
        if self._s is None:
            s = self._piqp.DenseSolver()
            s.settings.eps_abs = 1e-9
            s.settings.eps_rel = 0.0
            s.settings.verbose = False
            s.setup(H, g, A if self.ne else None, b if self.ne else None,
                    C if self.ni else None, lc if self.ni else None, u if self.ni else None,
                    lbox, ubox)
            self._s = s
        else:
            self._s.update(H, g, A if self.ne else None, b if self.ne else None,
                           C if self.ni else None, lc if self.ni else None,
                           u if self.ni else None, lbox, ubox)
        status = self._s.solve()
        res = self._s.result
        self.iterations = int(res.info.iter)
        self._x = res.x
        return status == self._piqp.PIQP_SOLVED


def fortran(c: Captured) -> Captured:
    """
    Copy a cycle with column-major matrices.

    PIQP's dense interface takes those: converted at capture time, not in the timed solve.
    """
    ne = c.split[2].shape[0]
    out = Captured(
        c.q, c.v, np.asfortranarray(c.H), c.g, c.M, c.lo, c.hi, c.H.shape[0], ne, c.x_ctrl
    )
    sp = list(out.split)
    sp[2], sp[4] = np.asfortranarray(c.M[:ne]), np.asfortranarray(c.M[ne:])
    out.split = tuple(sp)
    return out


def time_floor(model, cap, solver: str, nx: int, ne: int, ni: int, scale) -> dict:
    """
    Time computeAllTerms + one warm-started solve by ``solver`` of each captured cycle.

    The first solve (cold: the solver's setup) is not timed, as the controller's configuration
    cycle. Returns per cycle: 'total' and 'solve' (seconds), 'iterations', and over the run the
    'failures' and the largest deviation from the controller's solution 'max_rel_dev' (relative
    to max(1, |x|_inf)).
    """
    import gc
    import time

    import pinocchio as pin

    s = Solver(solver, nx, ne, ni, scale)
    if solver == 'piqp':
        cap = [fortran(c) for c in cap]
    data = model.createData()
    s.solve(cap[0])
    n = len(cap)
    total, solve, iters = np.empty(n), np.empty(n), np.empty(n)
    failures, dev = 0, 0.0
    pc = time.perf_counter
    gc.collect()
    gc.disable()
    try:
        for k, c in enumerate(cap):
            t0 = pc()
            pin.computeAllTerms(model, data, c.q, c.v)
            t1 = pc()
            ok = s.solve(c)
            t2 = pc()
            total[k], solve[k], iters[k] = t2 - t0, t2 - t1, s.iterations
            if ok:
                err = np.max(np.abs(s.x_physical() - c.x_ctrl))
                dev = max(dev, float(err / max(1.0, np.max(np.abs(c.x_ctrl)))))
            else:
                failures += 1
    finally:
        gc.enable()
    return {
        'total': total,
        'solve': solve,
        'iterations': iters,
        'failures': failures,
        'max_rel_dev': dev,
    }
