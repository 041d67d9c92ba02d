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
Common interface of the QP back-ends.

Problem form (sizes fixed at setup, values change every cycle):
    min 1/2 x^T H x + g^T x   s.t.   A x = b,   l <= C x <= u,   lbox <= x <= ubox

Budget: every solve is bounded by an *iteration cap*. The controller sets ``deadline`` (a
``time.perf_counter()`` instant, from the control period) before each solve; the back-end turns the
time left into iterations with its measured solve-time model (fixed cost + cost per iteration,
running estimates that preemption spikes barely move), never fewer than ``min_iterations`` (a
warm-started feasible cycle needs 1-5: being late alone never fails a cycle, and the outcome of a
solve does not depend on the machine's load) and never more than ``max_iterations``. A solve that
fails after a warm start is retried cold with what is left of the cap, unless the first attempt
used it all.
"""

from __future__ import annotations

from enum import Enum
import time

import numpy as np


def _robust(estimate: float, sample: float) -> float:
    """
    Update a running estimate that follows a rise quickly and a fall slowly.

    A harder problem: the cap must shrink at once. A sample far above it (a preempted solve) moves
    it at most to 1.6x.
    """
    if estimate == 0.0:
        return sample
    if sample > estimate:
        return 0.7 * estimate + 0.3 * min(sample, 3.0 * estimate)
    return 0.95 * estimate + 0.05 * sample


# share of the time left that the iteration cap is computed for: the cost of an iteration varies
# with the problem (a failing solve's iterations cost up to ~2.5x a warm feasible one's, measured
# with ProxQP), so the model's estimate may be low by that much on the first hard cycle without the
# cycle overrunning its budget
_TIME_SHARE = 0.4


class QPSolver(Enum):
    DAQP = 'daqp'
    PROXQP = 'proxqp'
    OSQP = 'osqp'

    @classmethod
    def from_string(cls, name: str) -> 'QPSolver':
        key = str(name).strip().lower().replace('-', '').replace('_', '')
        for s in cls:
            if s.value == key:
                return s
        raise ValueError(
            f"unknown QP solver '{name}' (expected one of: {', '.join(s.value for s in cls)})"
        )


class ReturnCode(Enum):
    SUCCESS = 'success'
    MAX_ITERATIONS = 'max_iterations_reached'
    PRIMAL_INFEASIBLE = 'primal_infeasible'
    DUAL_INFEASIBLE = 'dual_infeasible'
    NON_FINITE_PROBLEM = 'non_finite_problem'
    NON_FINITE_SOLUTION = 'non_finite_solution'
    SOLVER_ERROR = 'solver_error'
    NOT_SOLVED = 'not_solved'


class QPBackend:
    name = 'base'
    default_max_iterations = 1000

    min_iterations = 10

    def __init__(self, nx: int, n_eq: int, n_in: int):
        self.nx, self.n_eq, self.n_in = nx, n_eq, n_in
        self.x = np.zeros(nx)
        self.iterations = 0
        self.max_iterations = self.default_max_iterations
        self.deadline: float | None = None
        self._fixed = 0.0  # seconds of a solve of one or two iterations
        self._per = 0.0  # seconds per further iteration

    def iteration_cap(self, now: float | None = None) -> int:
        """
        Return the iterations allowed to the next solve (see the module's docstring).

        ``now``: the time.perf_counter() instant, when the caller has it.
        """
        cap, deadline, fixed = self.max_iterations, self.deadline, self._fixed
        if deadline is None or fixed <= 0.0:
            return cap
        if now is None:
            now = time.perf_counter()
        per = self._per or fixed
        n = (_TIME_SHARE * (deadline - now) - fixed) / per  # the further iterations that fit
        # min(cap, max(min_iterations, 1 + int(n))), in the control cycle's hot path
        least = self.min_iterations
        if n < least - 1:
            return least
        return 1 + int(n) if n < cap else cap  # (n may be inf: a solve model of ~0 s)

    def record(self, seconds: float, iterations: int) -> None:
        """
        Update the solve-time model t = fixed + (iterations - 1) * per with one solve.

        The estimates are robust running ones: a sample far above them (e.g. a preempted solve)
        moves them little.
        """
        it, fixed = int(iterations), self._fixed
        if it <= 2 or fixed == 0.0:
            self._fixed = _robust(fixed, seconds if it <= 2 else seconds / it)
        else:
            extra = seconds - fixed
            self._per = _robust(self._per, (extra if extra > 0.0 else 0.0) / (it - 1))

    def solve(self, H, g, A, b, C, lc, u, lbox, ubox) -> ReturnCode:
        raise NotImplementedError

    def reset(self) -> None:
        """Forget the warm start (next solve starts cold)."""
