"""Optimisation: the controller, its problem(s) and the QP back-ends."""
from .controller import Controller
from .problem_layout import ProblemLayout
from .resolution_strategy import ResolutionStrategy
from .solvers import QPSolver, ReturnCode
from .weighted_problem import WeightedProblem

__all__ = ["Controller", "ProblemLayout", "QPSolver", "ResolutionStrategy", "ReturnCode", "WeightedProblem"]
