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
"""Minimum-jerk point-to-point trajectory (fifth-order polynomial with zero boundary vel/acc)."""

from __future__ import annotations

import numpy as np


class MinJerkPositionTrajectory:
    """
    Position trajectory from ``start`` to ``end`` in ``duration`` seconds.

    The clock starts at the first :meth:`get_desired` call after :meth:`reset_trajectory`.
    """

    def __init__(self, duration: float):
        if not duration > 0.0:
            raise ValueError(f'trajectory duration must be > 0 s, got {duration}')
        self.duration = float(duration)
        self._start = np.zeros(3)
        self._delta = np.zeros(3)
        self._t0: float | None = None
        self._finished = False

    def reset_trajectory(self, start_position, end_position) -> None:
        self._start = np.array(start_position, dtype=float).reshape(-1)
        self._delta = np.array(end_position, dtype=float).reshape(-1) - self._start
        self._t0 = None
        self._finished = False

    def is_trajectory_finished(self) -> bool:
        return self._finished

    def get_desired(self, current_time: float):
        """Return (position, velocity, acceleration) at ``current_time``."""
        if self._t0 is None:
            self._t0 = current_time
        s = (current_time - self._t0) / self.duration
        if s >= 1.0:
            self._finished = True
            z = np.zeros_like(self._delta)
            return self._start + self._delta, z, z.copy()
        s = max(s, 0.0)
        T = self.duration
        p = self._start + self._delta * (10 * s**3 - 15 * s**4 + 6 * s**5)
        v = self._delta * (30 * s**2 - 60 * s**3 + 30 * s**4) / T
        a = self._delta * (60 * s - 180 * s**2 + 120 * s**3) / T**2
        return p, v, a
