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
"""QP back-ends."""

import numpy as np

from .availability import installed, resolve_solver
from .base import QPBackend, QPSolver, ReturnCode
from .daqp_backend import DAQPBackend
from .osqp_backend import OSQPBackend
from .proxqp_backend import ProxQPBackend
from .scaled_backend import ScaledBackend


def make_backend(
    solver: QPSolver, nx: int, n_eq: int, n_in: int, box: bool = True, scale=None
) -> QPBackend:
    """
    Make a back-end for problems of these sizes.

    ``box=False`` when lbox/ubox are always infinite; ``scale``: the variables' scale d (the
    solver works on x / d, see :mod:`.scaled_backend`), None or all ones for none.
    """
    scaled = scale is not None and bool(np.any(np.asarray(scale) != 1.0))
    if solver is QPSolver.DAQP:
        b = DAQPBackend(nx, n_eq, n_in)
    elif solver is QPSolver.OSQP:
        # with contacts, its polishing often fails on the degenerate wrench block: the ADMM iterate
        # itself must then agree with DAQP to 1e-6 (test_talos_balance.py): on Talos at 1e-9,
        # not at 1e-7
        b = OSQPBackend(nx, n_eq, n_in, eps=1e-9 if scaled else 1e-7)
    elif solver is QPSolver.PROXQP:
        # a scaled problem keeps dynamics rows with coefficients up to ~1e3 (M, J^T m g): ProxQP's
        # primal residual floors near 1e-9 there (at 1e-9 Talos's solves ran to the iteration
        # cap); 1e-8 still agrees with DAQP to 1e-6 (test_talos_balance.py)
        b = ProxQPBackend(nx, n_eq, n_in, box=box, eps_abs=1e-8 if scaled else 1e-9)
    else:
        raise ValueError(f'unsupported QP solver {solver!r}')
    return ScaledBackend(b, scale) if scaled else b


__all__ = [
    'QPBackend',
    'QPSolver',
    'ReturnCode',
    'DAQPBackend',
    'OSQPBackend',
    'ProxQPBackend',
    'ScaledBackend',
    'make_backend',
    'installed',
    'resolve_solver',
]
