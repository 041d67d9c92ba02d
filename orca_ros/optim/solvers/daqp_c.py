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
DAQP's C entry points, as the pinned daqp (0.11.0) exports them from its extension module.

The Python wrapper (``daqp.Model``) costs about as much per cycle as the small solve it wraps:
keyword arguments, contiguity checks, a settings dict, a result dict and copies. The compiled cycle
calls ``daqp_update_ldp`` and ``daqp_solve`` from its kernel instead (:mod:`.daqp_kernel`), on
structures laid out here with ctypes after DAQP's ``types.h`` and ``api.h``.

A wrong layout must not pass silently (DAQP reads whatever memory it is given): :func:`check`
runs after every set-up and compares what DAQP wrote into the workspace (sizes, constraint
states, every default setting) with what was given; any difference raises :class:`LayoutError`
and the controller keeps the Python wrapper.
"""

from __future__ import annotations

import ctypes as C

import numpy as np

from ...utils.optional_import import optional_import

_P = C.c_void_p
_D = C.c_double
_I = C.c_int

#: DAQP_UPDATE_* of constants.h: Rinv, M, v, d, sense (what daqp.Model.update passes)
UPDATE_ALL = 1 | 2 | 4 | 8 | 16
#: DAQP_DEFAULT_ITER_LIMIT
DEFAULT_ITER_LIMIT = 10000


class LayoutError(RuntimeError):
    """DAQP's structures are not laid out as this module declares them."""


class Problem(C.Structure):
    _fields_ = [('n', _I), ('m', _I), ('ms', _I), ('H', _P), ('f', _P), ('A', _P),
                ('bupper', _P), ('blower', _P), ('sense', _P), ('break_points', _P),
                ('nh', _I), ('problem_type', _I)]


class Result(C.Structure):
    _fields_ = [('x', _P), ('lam', _P), ('fval', _D), ('soft_slack', _D), ('exitflag', _I),
                ('iter', _I), ('nodes', _I), ('solve_time', _D), ('setup_time', _D)]


class Settings(C.Structure):
    _fields_ = [('primal_tol', _D), ('dual_tol', _D), ('zero_tol', _D), ('pivot_tol', _D),
                ('progress_tol', _D), ('cycle_tol', _I), ('iter_limit', _I), ('fval_bound', _D),
                ('eps_prox', _D), ('eta_prox', _D), ('rho_soft', _D), ('rel_subopt', _D),
                ('abs_subopt', _D), ('sing_tol', _D), ('refactor_tol', _D), ('time_limit', _D),
                ('w_soft', _D), ('eq_reduction', _I), ('presolve', _I)]


class WorkspaceHead(C.Structure):
    """DAQPWorkspace up to its settings (the fields read here); the rest is DAQP's."""

    _fields_ = [('qp', _P), ('n', _I), ('m', _I), ('ms', _I), ('M', _P), ('dupper', _P),
                ('dlower', _P), ('Rinv', _P), ('v', _P), ('sense', C.POINTER(_I)),
                ('scaling', _P), ('RinvD', _P), ('x', _P), ('xold', _P), ('lam', _P),
                ('lam_star', _P), ('u', _P), ('fval', _D), ('L', _P), ('D', _P), ('xldl', _P),
                ('zldl', _P), ('reuse_ind', _I), ('WS', _P), ('n_active', _I), ('iterations', _I),
                ('sing_ind', _I), ('prox_mask', _P), ('n_prox', _I), ('soft_slack', _D),
                ('settings', C.POINTER(Settings))]


#: bytes given to a workspace: DAQPWorkspace is ~0.4 kB in daqp 0.11; the rest stays zero
WORKSPACE_BYTES = 4096


class Library:
    """The extension module's C functions (ctypes for set-up, addresses for the kernel)."""

    def __init__(self):
        daqp = optional_import('daqp', "solver 'daqp'", 'or solver: proxqp / osqp')
        lib = C.CDLL(daqp.__file__)
        self.setup = lib.setup_daqp
        self.setup.argtypes, self.setup.restype = [_P, _P, _P], _I
        self.allocate_settings = lib.allocate_daqp_settings
        self.allocate_settings.argtypes, self.allocate_settings.restype = [_P], None
        self.default_settings = lib.daqp_default_settings
        self.default_settings.argtypes, self.default_settings.restype = [_P], None
        self.free_workspace = lib.free_daqp_workspace
        self.free_workspace.argtypes, self.free_workspace.restype = [_P], None
        self.free_ldp = lib.free_daqp_ldp
        self.free_ldp.argtypes, self.free_ldp.restype = [_P], None
        #: int daqp_update_ldp(int mask, DAQPWorkspace*, DAQPProblem*)
        self.update_address = C.cast(lib.daqp_update_ldp, _P).value
        #: void daqp_solve(DAQPResult*, DAQPWorkspace*)
        self.solve_address = C.cast(lib.daqp_solve, _P).value
        self._lib = lib


_LIBRARY: Library | None = None
_LIBC = C.CDLL(None)
_LIBC.free.argtypes, _LIBC.free.restype = [_P], None


def free(address: int) -> None:
    """Free memory DAQP allocated (malloc) and handed over."""
    _LIBC.free(address)


def library() -> Library:
    global _LIBRARY
    if _LIBRARY is None:
        _LIBRARY = Library()
    return _LIBRARY


def struct_in(array: np.ndarray, cls):
    """View ``cls`` over a numpy buffer (it keeps the memory; the kernel reads it too)."""
    if array.nbytes < C.sizeof(cls) or not array.flags.c_contiguous:
        raise LayoutError(f'{cls.__name__}: buffer too small or not contiguous')
    return cls.from_buffer(array)


def check(work: WorkspaceHead, problem: Problem, sense: np.ndarray, full: bool = True) -> None:
    """
    Raise LayoutError unless the workspace DAQP set up is laid out as declared.

    It must point to the problem and hold its sizes; with ``full`` (a workspace's first set-up:
    the layout is the library's, the same at every later one) also its constraint states in range
    and its settings equal, field by field, to those ``daqp_default_settings`` writes into a fresh
    structure.
    """
    if work.qp != C.addressof(problem):
        raise LayoutError('workspace does not point to the problem it was set up with')
    if (work.n, work.m, work.ms) != (problem.n, problem.m, problem.ms):
        raise LayoutError(
            f'workspace sizes {(work.n, work.m, work.ms)} != problem '
            f'{(problem.n, problem.m, problem.ms)}'
        )
    if problem.m and not bool(work.sense):
        raise LayoutError('workspace has no constraint states')
    if not full:
        return
    lib = library()
    # the set-up rewrites the states (active, immutable, zero rows...): within DAQP's 15 bits
    states = np.ctypeslib.as_array(work.sense, shape=(problem.m,)) if problem.m else sense[:0]
    if np.any((states < 0) | (states >= 1 << 15)):
        raise LayoutError('workspace constraint states out of range')
    if not bool(work.settings):
        raise LayoutError('workspace has no settings')
    expected = Settings()
    lib.default_settings(C.byref(expected))
    got = work.settings.contents
    for name, _ in Settings._fields_:
        if getattr(got, name) != getattr(expected, name):
            raise LayoutError(f'workspace setting {name}: {getattr(got, name)!r}')
