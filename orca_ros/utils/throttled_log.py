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
One log line per cause per period, whatever the message rate (no ROS).

A node fed bad data at 1 kHz must say what is wrong without flooding its log: each *cause* (a short
fixed key such as ``"state:limits"``) prints at most once per ``period``; lines held back are
counted and the count is appended to the next line of that cause. Causes come from a small fixed
vocabulary, so the tables stay small.
"""

from __future__ import annotations

import time


class ThrottledLog:
    def __init__(self, logger, period: float = 1.0, clock=time.monotonic):
        self._logger = logger
        self.period = float(period)
        self._clock = clock
        self._last: dict[str, float] = {}
        self._held: dict[str, int] = {}

    def __call__(self, level: str, cause: str, text: str) -> bool:
        """
        Log ``text`` at ``level`` unless ``cause`` was logged less than ``period`` ago.

        ``level`` is one of 'debug', 'info', 'warning', 'error'.

        Returns whether the line was printed.
        """
        now = self._clock()
        last = self._last.get(cause)
        if last is not None and now - last < self.period:
            self._held[cause] = self._held.get(cause, 0) + 1
            return False
        held = self._held.pop(cause, 0)
        if held:
            text = f'{text} (and {held} more like it since the last report)'
        self._last[cause] = now
        # one call line per severity: rclpy's logger binds a severity to each call site
        if level == 'error':
            self._logger.error(text)
        elif level == 'warning':
            self._logger.warning(text)
        elif level == 'info':
            self._logger.info(text)
        else:
            self._logger.debug(text)
        return True

    def due(self, cause: str) -> bool:
        """Whether a line of ``cause`` would be printed now (nothing is counted or logged)."""
        last = self._last.get(cause)
        return last is None or self._clock() - last >= self.period

    def forget(self, cause: str) -> None:
        """Let the next line of ``cause`` through at once (e.g. after the condition cleared)."""
        self._last.pop(cause, None)
        self._held.pop(cause, None)
