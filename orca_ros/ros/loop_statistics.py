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
The controller node's loop statistics: what its cycles counted and measured, over a window.

Written by the node's cycle, read by its ``/diagnostics`` report and its ``~/cycle_timing``
stream. The windows are bounded (``statistics_window`` cycles): nothing grows while the node
runs.
"""

from __future__ import annotations

import numpy as np

from ..utils.ring_buffer import RingBuffer


class LoopStatistics:
    """Counters and windows of the node's control loop (public fields, see each comment)."""

    def __init__(self, window: int):
        self.qp_failures = 0
        self.loop_cycles = 0  # cycles run with a state: solved, or safe without a solve (stale)
        self.last_qp_failure = None  # what the last failed cycle said
        self.contacts_relaxed_cycles = 0  # cycles solved with elastic contacts (see optim/)
        self.qp_conflict = ''  # what diagnose() said of the last failing spell
        self.solve_times = RingBuffer(window)
        self.cycle_stamps = RingBuffer(window)  # controller time of each solve (cycle_timing)
        self.loop_periods = RingBuffer(window)
        # state in to command out: from the reception of the state a command answers to its
        # publication
        self.latencies = RingBuffer(window)

    def summary(self, period: float):
        """
        Solve times, loop periods and latencies over the windows (``period``: the nominal one).

        A job's slices: one partition of a window per slice (each a fraction of a 1 kHz loop's
        period, even on a large window); ``yield from`` returns the numbers.
        """
        sol, per = self.solve_times, self.loop_periods
        solve_median, solve_p99 = sol.quantiles((0.5, 0.99))
        yield
        period_median, period_p99, period_p999 = per.quantiles((0.5, 0.99, 0.999))
        yield
        latency_median, latency_p99 = self.latencies.quantiles((0.5, 0.99))
        yield
        jitter = np.abs(per.values() - period) if len(per) else np.zeros(1)
        jitter_p99 = float(np.percentile(jitter, 99) * 1e3)
        yield
        return {
            'solve_median_us': solve_median * 1e6,
            'solve_p99_us': solve_p99 * 1e6,
            'solve_max_us': sol.max() * 1e6,
            'period_mean_ms': per.mean() * 1e3,
            'period_median_ms': period_median * 1e3,
            'period_p99_ms': period_p99 * 1e3,
            'period_p999_ms': period_p999 * 1e3,
            'period_max_ms': per.max() * 1e3,
            'latency_median_ms': latency_median * 1e3,
            'latency_p99_ms': latency_p99 * 1e3,
            'jitter_p99_ms': jitter_p99,
        }
