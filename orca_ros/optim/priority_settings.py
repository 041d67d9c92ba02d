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
The controller's settings between priority levels: GENERALIZED priorities, lower levels' damping.

A part of :class:`.controller.Controller` (a mixin: the same object). The values are read by
the priority levels (:mod:`.priority_levels`, :mod:`.generalized`) every cycle.
"""

from __future__ import annotations

import numpy as np

from .resolution_strategy import ResolutionStrategy


class PrioritySettingsMixin:
    """Priorities between tasks of different levels, and the damping of the levels below."""

    def set_priority(self, high: str, low: str, value: float) -> None:
        """
        GENERALIZED.

        Priority in [0, 1] of task ``high`` over task ``low`` (0 weighted, 1 strict); may change
        every cycle.

        ``high`` must sit on a higher level (smaller number) than ``low``.
        """
        if self.resolution_strategy is not ResolutionStrategy.GENERALIZED:
            raise ValueError(
                f"controller '{self.name}': priority values need the GENERALIZED strategy "
                f'(this one is {self.resolution_strategy.value})'
            )
        th, tl = self.get_task(high), self.get_task(low)
        if not th.level < tl.level:
            raise ValueError(
                f"set_priority('{high}', '{low}'): '{high}' (level {th.level}) must be on a "
                f"higher level than '{low}' (level {tl.level})"
            )
        self.priorities.set(high, low, value)

    def set_priority_matrix(self, names, matrix) -> None:
        """
        GENERALIZED.

        matrix[i][j] = priority of task names[i] over names[j]; only entries with level(i) <
        level(j) are read, the rest must be left at 0 or 1 (ignored).
        """
        m = np.asarray(matrix, dtype=float)
        if m.shape != (len(names), len(names)):
            raise ValueError(f'priority matrix must be {len(names)}x{len(names)}, got {m.shape}')
        for i, hi in enumerate(names):
            for j, lo in enumerate(names):
                if self.get_task(hi).level < self.get_task(lo).level:
                    self.set_priority(hi, lo, m[i, j])

    def get_priority(self, high: str, low: str) -> float:
        return self.priorities.get(high, low)

    def set_lower_level_damping(self, mu: float) -> None:
        """
        Damp every level below the first in time: + mu W ||x - x_prev||^2 (0: off; default 10).

        W: the level's own weights; see :meth:`LowerLevelProblem.set_temporal_damping`.
        """
        if self._levels is not None:
            self._levels.set_temporal_damping(mu)
        self._lower_damping = float(mu)
