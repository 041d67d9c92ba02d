"""QP back-ends."""
from .base import QPBackend, QPSolver, ReturnCode
from .daqp_backend import DAQPBackend
from .osqp_backend import OSQPBackend
from .proxqp_backend import ProxQPBackend


def make_backend(solver: QPSolver, nx: int, n_eq: int, n_in: int, box: bool = True) -> QPBackend:
    """A back-end for problems of these sizes; ``box=False`` when lbox/ubox are always infinite."""
    if solver is QPSolver.DAQP:
        return DAQPBackend(nx, n_eq, n_in)
    if solver is QPSolver.OSQP:
        return OSQPBackend(nx, n_eq, n_in)
    if solver is QPSolver.PROXQP:
        return ProxQPBackend(nx, n_eq, n_in, box=box)
    raise ValueError(f"unsupported QP solver {solver!r}")


__all__ = ["QPBackend", "QPSolver", "ReturnCode", "DAQPBackend", "OSQPBackend", "ProxQPBackend", "make_backend"]
