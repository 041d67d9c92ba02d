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
An obstacle's velocity from its successive poses (a perception's), for the collision constraint.

The constraint brakes for an obstacle closing in, not only for the arm, and carries a pose on
along its velocity between poses (``max_extrapolation``): a sparse pose is not taken for where
the obstacle is now. The velocity is the last two positions of different instants over their
time apart, when that is at most ``VELOCITY_WINDOW``.
"""

from __future__ import annotations

import numpy as np

#: poses at most this far apart [s] give a velocity: perceptions at 4 Hz and faster. A window
#: close to a perception's period gave its poses (apart by that period, give or take their
#: jitter) a velocity one time and none the next, and the obstacle stood still, then jumped,
#: stepping the torques (test_obstacle_updates.py's ball): keep it well above the period
VELOCITY_WINDOW = 0.25


class ObstacleVelocity:
    """The velocities of named obstacles, from the positions and times of their poses."""

    def __init__(self, window: float = VELOCITY_WINDOW):
        self.window = float(window)
        self._seen: dict = {}  # name -> (time, position, velocity, clock) of its last pose

    def observe(self, name: str, position, at: float, clock=None) -> np.ndarray | None:
        """
        Record the obstacle at ``position`` (world) at time ``at``; return its velocity, or None.

        None for its first pose, one more than ``window`` after the last, or one on another
        ``clock`` than the last (two clocks: no velocity across them). A pose of the same
        instant as the last gives the same velocity; an older one is not recorded.
        """
        position = np.array(position, dtype=float).reshape(3)
        seen = self._seen.get(name)
        if seen is not None and seen[3] != clock:
            seen = None
        velocity = None
        if seen is not None:
            if 0.0 < at - seen[0] <= self.window:
                velocity = (position - seen[1]) / (at - seen[0])
            elif at == seen[0]:
                velocity = seen[2]
        if seen is None or at > seen[0]:
            self._seen[name] = (at, position, velocity, clock)
        return velocity

    def forget(self, name: str | None = None) -> None:
        """Forget an obstacle's poses (all of them: None); its next pose has no velocity."""
        if name is None:
            self._seen.clear()
        else:
            self._seen.pop(name, None)
