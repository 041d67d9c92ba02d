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
The first level's DAQP back-end of the compiled cycle: DAQP's C solve called from a kernel.

The same problem, the same solver and the same warm start as the reference path's
``ScaledBackend(DAQPBackend)`` (:mod:`orca_ros.optim.solvers`): the QP is scaled, DAQP's
workspace keeps the last active set, a failed warm solve is retried cold with what is left of
the iteration cap, and a failed solve starts the next one cold (a fresh workspace, set up as
``daqp.Model.setup`` does). What goes is the Python around the solve (~3 us of the Panda's
cycle): scaling, update, solve and the solution in physical units are one kernel call
(:mod:`.daqp_kernel`); set-ups, rare, stay in Python (ctypes, :mod:`.daqp_c`).

Every set-up checks the structures' layout against what DAQP wrote (:func:`.daqp_c.check`);
a wrong layout raises before any solve is used.
"""

from __future__ import annotations

import ctypes as C
import time
import weakref

import numpy as np

from . import daqp_c, daqp_kernel as K
from ..solvers.base import QPBackend, ReturnCode
from ..solvers.daqp_backend import _EQUALITY, _FLAGS

_NON_FINITE = -100


def _free(lib, work: np.ndarray) -> None:
    address = work.ctypes.data
    lib.free_workspace(address)
    lib.free_ldp(address)


class DirectDAQPBackend(QPBackend):
    """``solve_stacked`` of DAQPBackend (scaled by ``scale``), by kernel."""

    name = 'daqp'

    def __init__(self, nx: int, n_eq: int, n_in: int, scale=None):
        super().__init__(nx, n_eq, n_in)
        self._lib = lib = daqp_c.library()
        m = n_eq + n_in
        d = np.ones(nx) if scale is None else np.asarray(scale, dtype=float).copy()
        self._d, self._dd, self._inv = d, np.outer(d, d), 1.0 / d
        self._Hs, self._gs = np.zeros((nx, nx)), np.zeros(nx)
        self._Ms = np.zeros((m, nx))
        self._los, self._his = np.zeros(nx + m), np.zeros(nx + m)
        self._xs, self._lam = np.zeros(nx), np.zeros(nx + m)
        self._sense = np.zeros(nx + m, dtype=np.intc)
        self._sense[nx: nx + n_eq] = _EQUALITY
        self._pbuf = np.zeros(C.sizeof(daqp_c.Problem) // 8 + 1, dtype=np.int64)
        p = self._problem = daqp_c.struct_in(self._pbuf, daqp_c.Problem)
        p.n, p.m, p.ms = nx, nx + m, nx
        p.H, p.f = self._Hs.ctypes.data, self._gs.ctypes.data
        p.A = self._Ms.ctypes.data if m else None
        p.bupper, p.blower = self._his.ctypes.data, self._los.ctypes.data
        self._rbuf = np.zeros(C.sizeof(daqp_c.Result) // 8 + 1, dtype=np.int64)
        r = self._result = daqp_c.struct_in(self._rbuf, daqp_c.Result)
        r.x, r.lam = self._xs.ctypes.data, self._lam.ctypes.data
        self._result_i32 = self._rbuf.view(np.int32)
        self._flag_at = daqp_c.Result.exitflag.offset // 4
        self._iter_at = daqp_c.Result.iter.offset // 4
        self._cap_at = daqp_c.Settings.iter_limit.offset // 4
        self._ptrs = np.array(
            [lib.update_address, lib.solve_address, 0, self._pbuf.ctypes.data,
             self._rbuf.ctypes.data], dtype=np.int64,
        )
        self._work = None  # the workspace's memory while it holds a set-up problem
        self._settings_i32 = None  # DAQP's settings (in memory DAQP owns), as int32
        self._no_settings = np.zeros(C.sizeof(daqp_c.Settings) // 4, dtype=np.int32)
        self._release = None
        self.x = np.zeros(nx)

    def compile_for(self, H, g, M, lo, hi) -> None:
        """Compile (or load) the kernel for these arrays' types (at configuration)."""
        if self._work is None:
            self._run_kernel(0, 0, H, g, M, lo, hi)

    def reset(self) -> None:
        """Forget the warm start: the next solve sets DAQP up again."""
        if self._release is not None:
            self._settings_i32 = None
            self._release()  # frees what DAQP allocated for the workspace
            self._release = self._work = None

    def _setup(self, H, g, M, lo, hi) -> int:
        """Set DAQP up on this cycle's problem, as daqp.Model.setup does; DAQP's flag."""
        self.reset()
        lib, p = self._lib, self._problem
        work = np.zeros(daqp_c.WORKSPACE_BYTES, dtype=np.uint8)
        address = work.ctypes.data
        # before anything can fail: whatever DAQP allocates is freed with the workspace
        release = weakref.finalize(self, _free, lib, work)
        lib.allocate_settings(address)
        K.scale(H, g, M, lo, hi, self._d, self._dd, self._inv, self._Hs, self._gs, self._Ms,
                self._los, self._his)
        p.sense = self._sense.ctypes.data
        flag = lib.setup(C.addressof(p), address, None)
        if flag < 0:
            release()
            return flag
        head = daqp_c.WorkspaceHead.from_buffer(work)
        daqp_c.check(head, p, self._sense)
        # from now on the workspace's own states: the next update keeps the active set
        p.sense = C.cast(head.sense, C.c_void_p).value
        settings = C.cast(head.settings, C.c_void_p).value
        self._settings_i32 = np.ctypeslib.as_array(
            (C.c_int32 * (C.sizeof(daqp_c.Settings) // 4)).from_address(settings)
        )
        self._work, self._release = work, release
        self._ptrs[K.WORK] = address
        return 0

    def _run(self, mask: int, cap: int, H, g, M, lo, hi) -> ReturnCode:
        t0 = time.perf_counter()
        flag, iters = self._run_kernel(mask, cap, H, g, M, lo, hi)
        self.iterations = int(iters)
        self.record(time.perf_counter() - t0, self.iterations)
        code = (
            ReturnCode.NON_FINITE_SOLUTION if flag == _NON_FINITE
            else _FLAGS.get(int(flag), ReturnCode.NOT_SOLVED)
        )
        if code is not ReturnCode.SUCCESS:
            self.reset()  # a failed solve leaves a useless active set: start cold next time
        return code

    def _run_kernel(self, mask, cap, H, g, M, lo, hi):
        settings = self._settings_i32 if self._settings_i32 is not None else self._no_settings
        return K.solve(
            self._ptrs, mask, cap, H, g, M, lo, hi, self._d, self._dd, self._inv, self._Hs,
            self._gs, self._Ms, self._los, self._his, self._xs, self.x, settings,
            self._result_i32, self._flag_at, self._iter_at, self._cap_at,
        )

    def _cold(self, cap: int, H, g, M, lo, hi) -> ReturnCode:
        flag = self._setup(H, g, M, lo, hi)
        if flag < 0:
            self.iterations = 0
            return _FLAGS.get(int(flag), ReturnCode.SOLVER_ERROR)
        return self._run(0, cap, H, g, M, lo, hi)

    def solve_stacked(self, H, g, M, lo, hi) -> ReturnCode:
        """Solve in DAQP's layout: M = [A; C], lo = [lbox; b; l], hi = [ubox; b; u]."""
        cap = self.iteration_cap()
        if self._work is None:
            return self._cold(cap, H, g, M, lo, hi)
        code = self._run(daqp_c.UPDATE_ALL, cap, H, g, M, lo, hi)
        if code is not ReturnCode.SUCCESS and self.iterations < cap:
            code = self._cold(cap - self.iterations, H, g, M, lo, hi)  # once more, cold
        return code

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        raise NotImplementedError('the compiled cycle solves its first level stacked')


_CHECKED: list = []  # [None] once the C path passed its check in this process, [why] if not


def unavailable_reason() -> str | None:
    """
    None when DAQP's C entry points can be used here; else why not (said once, in the log).

    Checked once per process on a small QP against the Python wrapper: its layout check
    (:func:`.daqp_c.check`) and the solution, to 1e-12.
    """
    if not _CHECKED:
        _CHECKED.append(_check())
    return _CHECKED[0]


def _check() -> str | None:
    import daqp  # noqa: PLC0415 - installed: library() found it

    H = np.array([[2.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 3.0]])
    g = np.array([1.0, -2.0, 0.5])
    M = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, 0.0]])
    lo = np.array([-1.0, -1.0, -1.0, 0.5, -np.inf])
    hi = np.array([1.0, 1.0, 1.0, 0.5, 0.2])
    try:
        b = DirectDAQPBackend(3, 1, 1)
        codes = [b.solve_stacked(H, g, M, lo, hi) for _ in range(2)]  # cold, then warm
    except (daqp_c.LayoutError, OSError, AttributeError) as exc:
        return f"DAQP's C entry points do not match this module ({exc})"
    sense = np.array([0, 0, 0, _EQUALITY, 0], dtype=np.intc)
    x, _, flag, _ = daqp.solve(H, g, M, hi, lo, sense)
    if codes != [ReturnCode.SUCCESS] * 2 or flag != 1 or np.max(np.abs(b.x - x)) > 1e-12:
        return f"DAQP's C entry points solve differently from its wrapper ({codes}, {b.x} vs {x})"
    return None
