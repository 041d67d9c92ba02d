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
The solve times of the controller's ``/diagnostics`` as a short history to plot (no ROS, no viser).

The controller reports, about 5 times a second, the median and 99th percentile of its last
solves (``solve_time_median_us``, ``solve_time_p99_us``, in microseconds). The history keeps those
values, as reported, over the last ``window`` seconds of the reports' stamps; a stamp that goes
back (a restarted controller, a restarted simulation clock) starts a new history.
"""

from __future__ import annotations

from collections import deque
import math

import numpy as np

KEYS = ('solve_time_median_us', 'solve_time_p99_us')


class SolveTimeHistory:
    def __init__(self, window: float = 30.0):
        self.window = float(window)
        self._points: deque = deque()  # (stamp [s], median [us], p99 [us])

    def add(self, stamp: float, values: dict) -> bool:
        """
        Take one report's values (key -> text); False when it has no finite solve times.

        Reports before the newest are dropped; one stamped before the newest kept starts anew.
        """
        try:
            median, p99 = (float(values[k]) for k in KEYS)
        except (KeyError, ValueError, TypeError):
            return False
        if not (math.isfinite(median) and math.isfinite(p99) and math.isfinite(stamp)):
            return False
        if self._points and stamp < self._points[-1][0]:
            self._points.clear()
        self._points.append((float(stamp), median, p99))
        while self._points[0][0] < stamp - self.window:
            self._points.popleft()
        return True

    def __len__(self) -> int:
        return len(self._points)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Time [s] relative to the newest report (<= 0), medians and p99s [us]."""
        if not self._points:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        a = np.array(self._points, dtype=float)
        return a[:, 0] - a[-1, 0], a[:, 1], a[:, 2]

    def title(self) -> str:
        """Return the newest values as the plot's title."""
        if not self._points:
            return 'solve time: none yet'
        _, median, p99 = self._points[-1]
        return f'solve time [us]: median {median:.1f}, p99 {p99:.1f}'
