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

from .base import QPBackend, QPSolver, ReturnCode
from .daqp_backend import DAQPBackend
from .osqp_backend import OSQPBackend
from .proxqp_backend import ProxQPBackend


def make_backend(solver: QPSolver, nx: int, n_eq: int, n_in: int, box: bool = True) -> QPBackend:
    """
    Make a back-end for problems of these sizes.

    ``box=False`` when lbox/ubox are always infinite.
    """
    if solver is QPSolver.DAQP:
        return DAQPBackend(nx, n_eq, n_in)
    if solver is QPSolver.OSQP:
        return OSQPBackend(nx, n_eq, n_in)
    if solver is QPSolver.PROXQP:
        return ProxQPBackend(nx, n_eq, n_in, box=box)
    raise ValueError(f'unsupported QP solver {solver!r}')


__all__ = [
    'QPBackend',
    'QPSolver',
    'ReturnCode',
    'DAQPBackend',
    'OSQPBackend',
    'ProxQPBackend',
    'make_backend',
]
