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
The first level's solve in a kernel: scaling, DAQP's C solve, the solution in physical units.

What :class:`~orca_ros.optim.solvers.ScaledBackend` and the DAQP wrapper do in Python, without
them: the problem is scaled (x = D x~, see :mod:`orca_ros.optim.solvers.scaled_backend`) into the
buffers DAQP's problem structure points to, ``daqp_update_ldp`` refreshes the workspace (the
active set of the last solve kept, as ``daqp.Model.update`` keeps it) and ``daqp_solve`` solves.
The C functions are called through their addresses (arguments, not constants: the kernel stays
cacheable across processes, where the addresses change).
"""

from __future__ import annotations

import math

from llvmlite import ir
from numba import types
from numba.experimental import structref
from numba.extending import intrinsic

from . import time_model
from .clock import monotonic_ns
from ...utils.jit import njit
from ...utils.struct_type import StructType

_I8P = ir.IntType(8).as_pointer()
_I32 = ir.IntType(32)


@intrinsic
def _update_ldp(typingctx, fn, mask, work, qp):
    """
    Call DAQP's update at address fn.

    C: ``int daqp_update_ldp(int mask, DAQPWorkspace*, DAQPProblem*)``.
    """
    if not all(isinstance(a, types.Integer) for a in (fn, mask, work, qp)):
        return None
    sig = types.int32(fn, mask, work, qp)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(_I32, [_I32, _I8P, _I8P])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [builder.trunc(args[1], _I32), builder.inttoptr(args[2], _I8P),
                                builder.inttoptr(args[3], _I8P)])

    return sig, codegen


@intrinsic
def _solve(typingctx, fn, res, work):
    """
    Call DAQP's solve at address fn.

    C: ``void daqp_solve(DAQPResult*, DAQPWorkspace*)``.
    """
    if not all(isinstance(a, types.Integer) for a in (fn, res, work)):
        return None
    sig = types.none(fn, res, work)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.VoidType(), [_I8P, _I8P])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(f, [builder.inttoptr(args[1], _I8P), builder.inttoptr(args[2], _I8P)])
        return context.get_dummy_value()

    return sig, codegen


#: ptrs: the addresses the kernel uses (WORK: 0 while no problem is set up), then the count of
#: DAQP's solves on the workspace (SOLVES)
UPDATE, SOLVE, WORK, PROBLEM, RESULT, SOLVES = range(6)

#: the solve's arrays (one StructRef argument: each array argument unboxed otherwise); the
#: level's H, g, M, lo, hi, the scale d (dd = d d^T, inv = 1 / d), DAQP's buffers (scaled
#: problem, scaled solution xs), the solution x (= base + the solver's: base 0 for a first
#: level, the level above's solution for a level solved for its step), DAQP's settings and
#: result as int32, and where in those the iteration limit, the exit flag and the iterations are
FIELDS = ('ptrs', 'H', 'g', 'M', 'lo', 'hi', 'd', 'dd', 'inv', 'Hs', 'gs', 'Ms', 'los', 'his',
          'xs', 'x', 'base', 'settings', 'result', 'cap_at', 'flag_at', 'iter_at')


@structref.register
class SolveStateType(StructType):
    """Its fields' types: see struct_type."""


class SolveState(structref.StructRefProxy):
    """The arrays of one first-level solve by kernel (fields: :data:`FIELDS`)."""


structref.define_proxy(SolveState, SolveStateType, list(FIELDS))


@njit
def make_solve_state(*fields):
    """Make a SolveState in compiled code: cached on disk, unlike the proxy's own constructor."""
    return SolveState(*fields)


@njit
def scale(s):
    """Write the problem in the solver's variables x~ = x / d into DAQP's buffers."""
    H, g, M, lo, hi, d, dd, inv = s.H, s.g, s.M, s.lo, s.hi, s.d, s.dd, s.inv
    Hs, gs, Ms, los, his = s.Hs, s.gs, s.Ms, s.los, s.his
    n = d.shape[0]
    for a in range(n):
        gs[a] = g[a] * d[a]
        for b in range(n):
            Hs[a, b] = H[a, b] * dd[a, b]
        los[a] = lo[a] * inv[a]
        his[a] = hi[a] * inv[a]
    for r in range(M.shape[0]):
        for b in range(n):
            Ms[r, b] = M[r, b] * d[b]
    for a in range(n, lo.shape[0]):
        los[a] = lo[a]
        his[a] = hi[a]


@njit
def solve(s, mask, cap):
    """
    Scale, update DAQP's workspace with ``mask`` (0: just set up), solve, unscale into x.

    Returns (DAQP's exit flag, its iterations); the flag of a failed update (< 0) without a
    solve; -100 for a solution that is not finite; (0, 0) without a workspace (nothing solved).
    """
    scale(s)
    ptrs = s.ptrs
    if ptrs[WORK] == 0:  # no workspace: a call that compiles (or loads) this kernel
        return 0, 0
    if mask:
        flag = _update_ldp(ptrs[UPDATE], mask, ptrs[WORK], ptrs[PROBLEM])
        if flag < 0:
            return flag, 0
    s.settings[s.cap_at] = cap
    _solve(ptrs[SOLVE], ptrs[RESULT], ptrs[WORK])
    ptrs[SOLVES] += 1
    flag = s.result[s.flag_at]
    iters = s.result[s.iter_at]
    if flag > 0:  # x written only when finite: it may be the level's own solution
        x, xs, d, base = s.x, s.xs, s.d, s.base
        total = 0.0
        for a in range(x.shape[0]):
            total += xs[a] * d[a]
        if not math.isfinite(total):
            return -100, iters
        for a in range(x.shape[0]):
            x[a] = base[a] + xs[a] * d[a]
    return flag, iters


_cap = njit(time_model.iteration_cap)
record_time = njit(time_model.record)


@njit
def budgeted(timing, deadline, most, least, clock):
    """
    Return (the iteration cap, now in ns): the time model's cap for the time left to deadline.

    ``timing``: the back-end's time model (:mod:`..solvers.time_model`); ``deadline``: a
    ``time.perf_counter`` instant (inf: none); ``most``, ``least``: its iteration bounds;
    ``clock``: clock_gettime's address (:mod:`.clock`).
    """
    start = monotonic_ns(clock)
    return _cap(timing, deadline - start * 1e-9, most, least), start


@njit
def timed_solve(s, mask, deadline, most, least, timing, clock):
    """
    Solve as :func:`solve` with the cap of the time model ``timing`` (see :func:`budgeted`).

    The model takes the solve's time when it succeeds. Returns (flag, iterations, the cap,
    the solve's nanoseconds).
    """
    cap, start = budgeted(timing, deadline, most, least, clock)
    flag, iters = solve(s, mask, cap)
    ns = monotonic_ns(clock) - start
    if flag == 1:
        record_time(timing, ns * 1e-9, iters)
    return flag, iters, cap, ns
