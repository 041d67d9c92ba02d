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
The controller's bound on every cycle's solves: a time budget and an iteration cap.

A part of :class:`.controller.Controller` (a mixin: the same object). The controller's update()
reads them every cycle: the cycle's deadline (the budget, else one control period) and the cap,
which the solvers' time models turn into each solve's iteration cap.
"""

from __future__ import annotations

import numpy as np


class SolverBudgetMixin:
    """The solve's time budget and iteration cap (``_time_budget``, ``_max_iterations``)."""

    def set_solver_budget(
        self, time_budget: float | None = None, max_iterations: int | None = None
    ) -> None:
        """
        Bound every cycle's solves.

        ``time_budget`` seconds for the whole cycle (None: one control period, the dt given to
        update) and at most ``max_iterations`` solver iterations per solve (None: the solver's
        default).

        A problem the solvers cannot solve within the budget fails with its ReturnCode.
        """
        if time_budget is not None and not (np.isfinite(time_budget) and time_budget > 0.0):
            raise ValueError(
                f"controller '{self.name}': time budget must be > 0 s, got {time_budget}"
            )
        if max_iterations is not None and int(max_iterations) < 1:
            raise ValueError(
                f"controller '{self.name}': max_iterations must be >= 1, got {max_iterations}"
            )
        self._time_budget = None if time_budget is None else float(time_budget)
        self._max_iterations = None if max_iterations is None else int(max_iterations)

    def get_solver_budget(self) -> tuple[float | None, int | None]:
        return self._time_budget, self._max_iterations
