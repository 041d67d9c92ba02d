"""Common interface of the QP back-ends.

Problem form (sizes fixed at setup, values change every cycle):
    min 1/2 x^T H x + g^T x   s.t.   A x = b,   l <= C x <= u,   lbox <= x <= ubox

Budget: every solve is bounded. ``max_iterations`` caps the solver's iterations and ``deadline`` (a
``time.perf_counter()`` instant, or None) the wall time; the controller sets the deadline from the control
period before each cycle. A solve that fails after a warm start is retried cold only while time is left.
"""
from __future__ import annotations

import time
from enum import Enum

import numpy as np


class QPSolver(Enum):
    DAQP = "daqp"
    PROXQP = "proxqp"
    OSQP = "osqp"

    @classmethod
    def from_string(cls, name: str) -> "QPSolver":
        key = str(name).strip().lower().replace("-", "").replace("_", "")
        for s in cls:
            if s.value == key:
                return s
        raise ValueError(f"unknown QP solver '{name}' (expected one of: {', '.join(s.value for s in cls)})")


class ReturnCode(Enum):
    SUCCESS = "success"
    MAX_ITERATIONS = "max_iterations_reached"
    TIME_LIMIT = "time_limit_reached"
    PRIMAL_INFEASIBLE = "primal_infeasible"
    DUAL_INFEASIBLE = "dual_infeasible"
    NON_FINITE_PROBLEM = "non_finite_problem"
    NON_FINITE_SOLUTION = "non_finite_solution"
    SOLVER_ERROR = "solver_error"
    NOT_SOLVED = "not_solved"


class QPBackend:
    name = "base"
    default_max_iterations = 1000

    def __init__(self, nx: int, n_eq: int, n_in: int):
        self.nx, self.n_eq, self.n_in = nx, n_eq, n_in
        self.x = np.zeros(nx)
        self.iterations = 0
        self.max_iterations = self.default_max_iterations
        self.deadline: float | None = None

    def remaining(self) -> float:
        """Seconds left before the deadline (inf without one)."""
        return np.inf if self.deadline is None else self.deadline - time.perf_counter()

    def budget_left(self) -> bool:
        return self.deadline is None or time.perf_counter() < self.deadline

    def solve(self, H, g, A, b, C, l, u, lbox, ubox) -> ReturnCode:
        raise NotImplementedError

    def reset(self) -> None:
        """Forget the warm start (next solve starts cold)."""
