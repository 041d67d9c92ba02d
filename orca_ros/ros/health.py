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
What the controller's ``/diagnostics`` says, decided without ROS (so it can be tested on its own).

ERROR: the safe command is going out because something is wrong (stale state, QP failing,
non-finite output), or QPs failed since the last report. WARN: waiting for the first state, loop
overruns or jitter since the last report, a priority level dropped, a task whose error stays large
(target unreachable?). OK otherwise, including a deliberate hold (``~/enable false``), which says
so in the message. Each report covers what happened since the previous one, so a fault shows within
one diagnostics period and clears one period after it ends.
"""

from __future__ import annotations

import numpy as np

OK, WARN, ERROR = 0, 1, 2


class TaskErrorWatch:
    """
    Flag a task whose error norm stays above ``threshold`` for too long.

    Too long: more than ``duration`` seconds.
    """

    def __init__(self, threshold: float, duration: float):
        self.threshold, self.duration = float(threshold), float(duration)
        self._since: dict[str, float] = {}
        self.norms: dict[str, float] = {}

    def observe(self, name: str, error_norm: float, t: float) -> None:
        self.norms[name] = error_norm
        if error_norm > self.threshold:
            self._since.setdefault(name, t)
        else:
            self._since.pop(name, None)

    def forget(self, name: str) -> None:
        self._since.pop(name, None)

    def persistent(self, t: float) -> list[tuple[str, float, float]]:
        """(task, error norm, seconds above the threshold) of the tasks past ``duration``."""
        return [
            (n, self.norms.get(n, 0.0), t - t0)
            for n, t0 in self._since.items()
            if t - t0 > self.duration
        ]


def persistent_error_text(name: str, norm: float, duration: float) -> str:
    """Say, for /diagnostics and the log, that a task's error stays large."""
    return f"task '{name}' error {norm:.3g} for {duration:.1f} s (target unreachable?)"


def assess(
    *,
    have_state: bool,
    state_age: float,
    state_timeout: float,
    safe_reason: str | None,
    safe_cause: str | None,
    qp_failures: int,
    dropped_levels: int,
    periods: np.ndarray,
    nominal_period: float,
    check_periods: bool,
    overrun_factor: float,
    persistent_errors,
    interval: float = 0.0,
    last_failure: str | None = None,
) -> tuple[int, str]:
    """(level, message) for one report; the counters are those since the previous report."""
    errors, warns, infos = [], [], []
    if not have_state:
        warns.append('waiting for joint_states')
    elif state_age > state_timeout and safe_cause != 'safe:stale':
        errors.append(f'joint state stale: none valid for {state_age:.2f} s')
    if safe_reason is not None:
        (infos if safe_cause == 'safe:disabled' else errors).append(
            f'holding: {safe_reason}'
            if safe_cause == 'safe:disabled'
            else f'safe command: {safe_reason}'
        )
    if qp_failures and safe_cause != 'safe:qp':
        # recovered since: the count, and what the last failure was
        last = f' (last: {last_failure})' if last_failure else ''
        errors.append(f'{qp_failures} QP failure(s) since the last report{last}')
    if dropped_levels:
        warns.append(f'{dropped_levels} cycle(s) dropped a priority level since the last report')
    expected = interval / nominal_period if nominal_period > 0 else 0.0
    if check_periods and have_state and expected >= 10 and periods.size < 0.5 * expected:
        # too few cycles to judge their periods: that itself is the overrun (a starved loop)
        warns.append(
            f'loop overruns: {periods.size} cycles in {interval * 1e3:.0f} ms '
            f'({expected:.0f} expected at a {nominal_period * 1e3:.2f} ms period)'
        )
    elif check_periods and periods.size >= 10:
        limit = overrun_factor * nominal_period
        over = int(np.count_nonzero(periods > limit))
        p99 = float(np.quantile(periods, 0.99))
        if p99 > limit or periods.mean() > 1.1 * nominal_period:
            warns.append(
                f'loop overruns: {over} of {periods.size} periods above {limit * 1e3:.2f} ms '
                f'(p99 {p99 * 1e3:.2f} ms, mean {periods.mean() * 1e3:.2f} ms for a '
                f'{nominal_period * 1e3:.2f} ms period)'
            )
    for name, norm, dur in persistent_errors:
        warns.append(persistent_error_text(name, norm, dur))
    if errors:
        return ERROR, '; '.join(errors + warns)
    if warns:
        return WARN, '; '.join(warns + infos)
    return OK, infos[0] if infos else 'controlling'
