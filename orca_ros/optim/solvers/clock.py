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
The monotonic clock inside a kernel: what ``time.perf_counter`` reads, without leaving it.

A kernel that solves times its own solve (the solver's time model, :mod:`..solvers.base`,
wants the solve alone, not the rows filled before it in the same call). It calls the C
library's ``clock_gettime(CLOCK_MONOTONIC)``, the clock ``time.perf_counter`` and
``time.monotonic_ns`` read on Linux, through its address (an argument: the kernel stays
cacheable across processes). :func:`unavailable_reason` checks it against
``time.monotonic_ns`` once per process; where it does not hold, the kernels are not given it.
"""

from __future__ import annotations

import ctypes
import sys
import time

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
import numpy as np

from ...utils.jit import njit

_CLOCK_MONOTONIC = 1  # Linux's
_I32, _I64 = ir.IntType(32), ir.IntType(64)


@intrinsic
def monotonic_ns(typingctx, fn):
    """
    Read the monotonic clock in nanoseconds, by ``clock_gettime`` at address fn.

    C: ``int clock_gettime(clockid_t, struct timespec *)``; timespec is two 64-bit words (LP64).
    """
    if not isinstance(fn, types.Integer):
        return None
    sig = types.int64(fn)

    def codegen(context, builder, signature, args):
        ts = cgutils.alloca_once(builder, ir.ArrayType(_I64, 2))  # in the entry block
        fnty = ir.FunctionType(_I32, [_I32, ir.IntType(8).as_pointer()])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(f, [ir.Constant(_I32, _CLOCK_MONOTONIC),
                         builder.bitcast(ts, ir.IntType(8).as_pointer())])
        zero = ir.Constant(_I32, 0)
        sec = builder.load(builder.gep(ts, [zero, zero]))
        nsec = builder.load(builder.gep(ts, [zero, ir.Constant(_I32, 1)]))
        return builder.add(builder.mul(sec, ir.Constant(_I64, 1_000_000_000)), nsec)

    return sig, codegen


@njit
def _read(fn):
    return monotonic_ns(fn)


def address() -> int:
    """Return the address of the C library's clock_gettime (0: none found)."""
    try:
        return ctypes.cast(ctypes.CDLL(None).clock_gettime, ctypes.c_void_p).value or 0
    except (OSError, AttributeError):
        return 0


_CHECKED: list = []  # [None] once the clock passed its check in this process, [why] if not


def unavailable_reason() -> str | None:
    """None when kernels can read the clock here; else why not (the caller says it once)."""
    if not _CHECKED:
        _CHECKED.append(_check())
    return _CHECKED[0]


def _check() -> str | None:
    if not sys.platform.startswith('linux') or np.dtype(np.intp).itemsize != 8:
        return 'the kernels read the clock on 64-bit Linux only'
    fn = address()
    if not fn:
        return "the C library's clock_gettime was not found"
    _read(fn)  # compiled (or loaded) before the comparison
    before = time.monotonic_ns()
    ours = _read(fn)
    after = time.monotonic_ns()
    if not before <= ours <= after:
        return f'clock_gettime by kernel read {ours} ns, outside [{before}, {after}]'
    # deadlines are time.perf_counter() instants: the same clock, in seconds
    first = time.perf_counter()
    ours = _read(fn) * 1e-9
    if not first - 1e-6 <= ours <= time.perf_counter() + 1e-6:
        return f'time.perf_counter is not the monotonic clock here ({first} s, {ours} s)'
    return None
