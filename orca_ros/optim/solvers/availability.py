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
Which QP solvers are installed, and what runs when the default is not.

Under an apt-installed ROS 2 (``rosdep install``), ProxQP comes with its rosdep key
(``proxsuite``); DAQP, the default and the fastest on the controller's QPs, has no rosdep key and
comes from pip. A controller asked for DAQP where it is missing falls back to ProxQP and says so in
one line naming the pip line; one asked for any other missing solver refuses with its pip line.
"""

from __future__ import annotations

import importlib.util

from .base import QPSolver
from ...utils.optional_import import MissingDependency, PIP

#: the Python module each solver needs
MODULE = {QPSolver.DAQP: 'daqp', QPSolver.PROXQP: 'proxsuite', QPSolver.OSQP: 'osqp'}
#: where the default is missing, the solver that rosdep installs
FALLBACK = QPSolver.PROXQP


def installed(solver: QPSolver) -> bool:
    """Return whether the solver's Python module can be imported."""
    try:
        return importlib.util.find_spec(MODULE[solver]) is not None
    except (ImportError, ValueError):  # a module set to None in sys.modules, or broken
        return False


def resolve_solver(solver: QPSolver) -> tuple[QPSolver, str]:
    """
    Return the solver that will run and, when it is not the one asked for, the warning to log.

    DAQP missing: ProxQP, with a warning naming DAQP's pip line. Any other missing solver (or
    DAQP and ProxQP both missing): MissingDependency naming the pip line.
    """
    if installed(solver):
        return solver, ''
    module = MODULE[solver]
    if solver is QPSolver.DAQP and installed(FALLBACK):
        return FALLBACK, (
            "solver 'daqp' (the default, the fastest on these QPs) is not installed: "
            f"pip install {PIP[module]}; using '{FALLBACK.value}' instead (rosdep key "
            f'{MODULE[FALLBACK]}), which may need more than a 1 ms control period on large '
            'problems'
        )
    raise MissingDependency(
        f"solver '{solver.value}' needs the Python package '{module}': pip install {PIP[module]}"
    )
