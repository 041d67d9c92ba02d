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
``daqp.Model.setup`` does). What goes is the Python around the solve (a noticeable part of a
small arm's cycle): scaling, update, solve and the solution in physical units are one kernel call
(:mod:`.daqp_kernel`); set-ups, rare, stay in Python (ctypes, :mod:`.daqp_c`).

A workspace's first set-up checks the structures' layout against what DAQP wrote
(:func:`.daqp_c.check`) before anything is written into the workspace; a wrong layout raises
before any solve is used. Later set-ups (after each failed solve: every cycle of a spell of
infeasible problems) check that the workspace points to the problem and holds its sizes; the
layout is the library's and does not change.
DAQP's structures live in memory owned here, its workspace set up again in place after a
failure; the settings it allocates are replaced by ours once checked (their iteration limit is
written by the kernel), so the kernel's arrays never change.
"""

from __future__ import annotations

import ctypes as C
import time
import weakref

import numpy as np

from . import clock, daqp_c, daqp_kernel as K
from .base import QPBackend, ReturnCode
from .daqp_backend import _EQUALITY, _FLAGS
from ...utils.jit import entry

_NON_FINITE = -100
_NO_DEADLINE = float('inf')  # (a kernel's deadline)


class DirectDAQPBackend(QPBackend):
    """``solve_stacked`` of DAQPBackend (scaled by ``scale``), by kernel."""

    name = 'daqp'

    def __init__(self, nx: int, n_eq: int, n_in: int, scale=None):
        super().__init__(nx, n_eq, n_in)
        self._lib = lib = daqp_c.library()
        m = n_eq + n_in
        d = np.ones(nx) if scale is None else np.asarray(scale, dtype=float).copy()
        self._sense = np.zeros(nx + m, dtype=np.intc)
        self._sense[nx: nx + n_eq] = _EQUALITY
        # DAQP's structures in memory owned here (8-byte words: aligned for its pointers):
        # the problem, the result, the settings (given to the workspace: DAQP does not free
        # them, see _release) and the workspace, set up again in place after a failure
        self._pbuf = _words(daqp_c.Problem)
        self._rbuf = _words(daqp_c.Result)
        self._sbuf = _words(daqp_c.Settings)
        self._wbuf = np.zeros(daqp_c.WORKSPACE_BYTES // 8, dtype=np.int64)
        lib.default_settings(self._sbuf.ctypes.data)
        self._work = daqp_c.struct_in(self._wbuf, daqp_c.WorkspaceHead)
        self.warm = False
        self._checked = False  # the workspace's layout checked in full (its first set-up)
        self._states = None  # the workspace's constraint flags (its active set), while set up
        self._cold_at = -2  # the count of solves when the active set was last cleared
        self._failure = None  # the code of a failed solve that started cold (solve_cold)
        self._ours = [False]  # the workspace holds our settings (put there once it checked)
        # the finalizer gets the workspace's view, not the module's layout: a layout looked up
        # when the collector runs may not be the one this workspace was set up and checked with
        self._finalizer = weakref.finalize(self, _release, lib, self._wbuf, self._work, self._ours)
        # the state's arrays (the kernel's StructRef cannot be read from Python)
        a = self._arrays = {
            'ptrs': np.array([lib.update_address, lib.solve_address, 0, self._pbuf.ctypes.data,
                              self._rbuf.ctypes.data, 0], dtype=np.int64),
            'H': np.zeros((nx, nx)), 'g': np.zeros(nx), 'M': np.zeros((m, nx)),
            'lo': np.zeros(nx + m), 'hi': np.zeros(nx + m),
            'd': d, 'dd': np.outer(d, d), 'inv': 1.0 / d,
            'Hs': np.zeros((nx, nx)), 'gs': np.zeros(nx), 'Ms': np.zeros((m, nx)),
            'los': np.zeros(nx + m), 'his': np.zeros(nx + m), 'xs': np.zeros(nx),
            'x': np.zeros(nx), 'base': np.zeros(nx),
            'settings': self._sbuf.view(np.int32), 'result': self._rbuf.view(np.int32),
            'cap_at': daqp_c.Settings.iter_limit.offset // 4,
            'flag_at': daqp_c.Result.exitflag.offset // 4,
            'iter_at': daqp_c.Result.iter.offset // 4,
        }
        self._ptrs = a['ptrs']
        self.clock = clock.address()  # (for kernels that time their solve: 0 if none)
        p = self._problem = daqp_c.struct_in(self._pbuf, daqp_c.Problem)
        # the addresses a set-up passes (the buffers never move)
        self._p_addr, self._w_addr = C.addressof(p), self._wbuf.ctypes.data
        self._sense_addr = self._sense.ctypes.data
        self._our_settings = C.cast(self._sbuf.ctypes.data, C.POINTER(daqp_c.Settings))
        p.n, p.m, p.ms = nx, nx + m, nx
        p.H, p.f = a['Hs'].ctypes.data, a['gs'].ctypes.data
        p.A = a['Ms'].ctypes.data if m else None
        p.bupper, p.blower = a['his'].ctypes.data, a['los'].ctypes.data
        r = daqp_c.struct_in(self._rbuf, daqp_c.Result)
        self._lam = np.zeros(nx + m)
        r.x, r.lam = a['xs'].ctypes.data, self._lam.ctypes.data
        self.x = a['x']
        self.solve_state = K.make_solve_state(*(a[f] for f in K.FIELDS))
        # the solve kernel for the state's types, called without the dispatcher's type
        # resolution (utils.jit.entry); again in bind(), for the level's arrays' types
        self._solve = entry(K.solve, self.solve_state, 0, 0)
        self._bound = None  # the level's arrays the state holds (bind)

    def write_into(self, x: np.ndarray, base: np.ndarray | None = None) -> None:
        """
        Write the solution into ``x`` (the level's own, float64 of size nx) from now on.

        The kernel writes it only when it is finite (else the solve fails, x untouched): the
        level neither checks nor copies it again (WeightedProblem.solve). With ``base``, x is
        base + the solution (a level solved for its step from the solution above).
        """
        self._arrays['x'] = self.x = x
        if base is not None:
            self._arrays['base'] = base
        self.solve_state = K.make_solve_state(*(self._arrays[f] for f in K.FIELDS))
        self._solve = entry(K.solve, self.solve_state, 0, 0)

    def bind(self, H, g, M, lo, hi) -> None:
        """Read the level's problem from these arrays (the same every cycle)."""
        self._arrays.update(H=H, g=g, M=M, lo=lo, hi=hi)
        self.solve_state = K.make_solve_state(*(self._arrays[f] for f in K.FIELDS))
        self._solve = entry(K.solve, self.solve_state, 0, 0)  # for these arrays' types
        self._bound = (H, g, M, lo, hi)

    def compile_for(self, H, g, M, lo, hi) -> None:
        """Compile (or load) the kernel for these arrays' types (at configuration)."""
        self.bind(H, g, M, lo, hi)
        if not self.warm:
            self._solve(self.solve_state, 0, 0)

    def reset(self) -> None:
        """Forget the workspace: the next solve sets DAQP up again."""
        if self.warm:
            _release(self._lib, self._wbuf, self._work, self._ours)
            self.warm = False
            self._ptrs[K.WORK] = 0
            self._states = None

    def restart(self) -> None:
        """
        Start the next solve cold on the same workspace: the active set cleared, nothing freed.

        DAQP's update with the sense flags (UPDATE_ALL) activates the constraints the
        workspace's flags mark active: the last solve's active set, the warm start. Written
        back to the problem's own flags (the equalities only), that update starts from the
        empty active set as a set-up does, without DAQP's allocation and release.
        """
        if self._states is not None:
            self._states[:] = self._sense
            self._cold_at = int(self._ptrs[K.SOLVES])

    @property
    def failed_cold(self) -> bool:
        """Say whether the last solve started from the empty active set (a retry is no use)."""
        return int(self._ptrs[K.SOLVES]) == self._cold_at + 1

    def _setup(self) -> int:
        """Set DAQP up on this cycle's problem, as daqp.Model.setup does; DAQP's flag."""
        self.reset()
        lib, p, work = self._lib, self._problem, self._work
        K.scale(self.solve_state)
        p.sense = self._sense_addr
        # nothing is written into the workspace before its layout is checked: DAQP allocates
        # its own settings here, checked against the defaults, then replaced by ours
        flag = lib.setup(self._p_addr, self._w_addr, None)
        self.warm = True  # whatever it allocated is freed by the next reset
        if flag < 0:
            self.reset()
            return flag
        daqp_c.check(work, p, self._sense, full=not self._checked)
        self._checked = True
        theirs = C.cast(work.settings, C.c_void_p).value
        work.settings = self._our_settings
        self._ours[0] = True
        daqp_c.free(theirs)
        # from now on the workspace's own states: the next update keeps the active set
        p.sense = C.cast(work.sense, C.c_void_p).value
        self._states = np.ctypeslib.as_array(work.sense, shape=(p.m,)) if p.m else None
        self._ptrs[K.WORK] = self._w_addr
        self._cold_at = int(self._ptrs[K.SOLVES])
        return 0

    def _run(self, mask: int, cap: int) -> ReturnCode:
        t0 = time.perf_counter()
        flag, iters = self._solve(self.solve_state, mask, cap)
        return self.ran(flag, iters, time.perf_counter() - t0)

    def ran(self, flag: int, iters: int, seconds: float) -> ReturnCode:
        """Return the code of a solve of ``seconds`` (the time model updated, reset on failure)."""
        self.iterations = iters
        self.record(seconds, iters)
        if flag == 1:
            return ReturnCode.SUCCESS
        code = (
            ReturnCode.NON_FINITE_SOLUTION if flag == _NON_FINITE
            else _FLAGS.get(int(flag), ReturnCode.NOT_SOLVED)
        )
        if code is not ReturnCode.SUCCESS:
            # a retry from the empty active set (solve_cold) repeats a solve that started there
            self._failure = None if not self.failed_cold else code
            self.restart()  # a failed solve leaves a useless active set: start cold next time
        return code

    def solve_cold(self, cap: int) -> ReturnCode:
        """
        Solve from the empty active set: on the workspace there is, else on a new one.

        After a failed solve that started there (the one after a failure), its code: the same
        solve again would fail the same way.
        """
        if self.warm and self._states is not None:
            failure, self._failure = self._failure, None
            if failure is not None:
                return failure
            self.restart()
            return self._run(daqp_c.UPDATE_ALL, cap)
        flag = self._setup()
        if flag < 0:
            self.iterations = 0
            return _FLAGS.get(int(flag), ReturnCode.SOLVER_ERROR)
        return self._run(0, cap)

    def solve_stacked(self, H, g, M, lo, hi) -> ReturnCode:
        """Solve in DAQP's layout: M = [A; C], lo = [lbox; b; l], hi = [ubox; b; u]."""
        b = self._bound
        if b is None or H is not b[0] or g is not b[1] or M is not b[2] or lo is not b[3] \
                or hi is not b[4]:
            self.bind(H, g, M, lo, hi)
        return self.solve_bound()

    def solve_bound(self) -> ReturnCode:
        """Solve the problem of the arrays bound last (bind, solve_stacked)."""
        cap = self.iteration_cap()
        if not self.warm:
            return self.solve_cold(cap)
        code = self._run(daqp_c.UPDATE_ALL, cap)
        if code is not ReturnCode.SUCCESS and self.iterations < cap:
            code = self.solve_cold(cap - self.iterations)  # once more, cold
        return code

    def solve_prepared(self, fused, pre, prepared: int):
        """
        Solve after a kernel that writes the bound arrays: ``fused(pre, state, mask, budget...)``.

        It prepares, then solves as :func:`.daqp_kernel.timed_solve` does (one call when warm,
        the cap and the time model in the kernel); with mask < 0 it only prepares (before a
        cold set-up), returning ``prepared`` when it did. Returns the ReturnCode, or the
        preparation's flag (an int below ``prepared``) when it did not solve.
        """
        deadline = _NO_DEADLINE if self.deadline is None else self.deadline
        if not self.warm:
            flag = fused(pre, self.solve_state, -1, deadline, 0, 0, self.timing, self.clock)[0]
            return flag if flag != prepared else self.solve_cold(self.iteration_cap())
        flag, iters, cap, ns = fused(pre, self.solve_state, daqp_c.UPDATE_ALL, deadline,
                                     self.max_iterations, self.min_iterations, self.timing,
                                     self.clock)
        if flag == 1:  # (the time model updated by the kernel)
            self.iterations = iters
            return ReturnCode.SUCCESS
        return self.prepared_failed(flag, iters, cap, ns, prepared)

    def prepared_failed(self, flag: int, iters: int, cap: int, ns: int, prepared: int):
        """
        Finish a warm call of ``fused`` (solve_prepared) that did not succeed.

        Its outcome: (flag, iterations, cap, nanoseconds); returns as solve_prepared.
        """
        if flag < prepared:
            return flag
        code = self.ran(flag, iters, ns * 1e-9)
        if code is not ReturnCode.SUCCESS and iters < cap:
            code = self.solve_cold(cap - iters)  # once more, cold
        return code

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        raise NotImplementedError('the compiled cycle solves its first level stacked')


def _words(cls) -> np.ndarray:
    return np.zeros(C.sizeof(cls) // 8 + 1, dtype=np.int64)


def _release(lib, wbuf: np.ndarray, work, ours: list) -> None:
    """
    Free what DAQP allocated for the workspace in ``wbuf`` (our settings excepted).

    Our settings are taken out of it first (DAQP would free them: numpy owns them) through
    ``work``, the view over ``wbuf`` the workspace was made with.
    """
    if not wbuf.any():
        return  # nothing set up
    if ours[0]:
        work.settings = None
        ours[0] = False
    address = wbuf.ctypes.data
    lib.free_workspace(address)
    lib.free_ldp(address)
    wbuf[:] = 0


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
