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
Joint velocities from positions, for drivers that publish none: filtered differences.

v_raw = (q_k - q_{k-1}) / (t_k - t_{k-1}), low-passed at ``cutoff`` Hz (first order, exact for
any step: v += (1 - exp(-dt / tau)) (v_raw - v), tau = 1 / (2 pi cutoff)). The default 100 Hz
lags 1.6 ms: a torque loop at 1 kHz keeps its damping, and encoder quantisation (a count per
cycle) is smoothed tenfold. The first reading, or one after a gap longer than ``max_gap`` (or a
clock that went back by more than that: a simulation restarted, unstamped readings timed on
receipt before stamped ones), gives zero velocities (nothing to differentiate); a reading of the
same or a slightly older instant changes nothing.
"""

from __future__ import annotations

import math

import numpy as np


class VelocityEstimator:
    def __init__(self, size: int, cutoff: float = 100.0, max_gap: float = 0.1):
        if not (math.isfinite(cutoff) and cutoff > 0.0):
            raise ValueError(f'velocity estimate cutoff must be finite and > 0, got {cutoff}')
        self.tau = 1.0 / (2.0 * math.pi * float(cutoff))
        self.max_gap = float(max_gap)
        self.v = np.zeros(size)
        self._q = np.zeros(size)
        self._t: float | None = None

    def update(self, q: np.ndarray, t: float) -> np.ndarray:
        """Take the positions ``q`` read at time ``t`` [s]; return the estimate (array reused)."""
        prev = self._t
        if prev is not None and prev - self.max_gap <= t <= prev:
            return self.v  # the same instant again
        if prev is None or abs(t - prev) > self.max_gap:
            self.v[:] = 0.0
        else:
            dt = t - prev
            gain = 1.0 - math.exp(-dt / self.tau)
            self.v += gain * ((q - self._q) / dt - self.v)
        self._q[:] = q
        self._t = t
        return self.v
