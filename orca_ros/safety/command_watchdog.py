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
The hardware side's guard: without a fresh command for ``timeout`` seconds, hold (no ROS).

What a drive or a ros2_control hardware interface does when its controller goes silent (crashed,
killed, starved of CPU, network cut): it does not keep the last torque on. Here the last command
fades over ``ramp`` into the hold of :class:`SafeCommand` (gravity + mass-weighted damping, within
the torque limits) and stays there until the next command, which applies at once. Before the first
command the robot is held too (the brakes of a real arm). Time is whatever clock the caller uses:
the simulator's, so a slowed machine slows both sides alike.
"""

from __future__ import annotations

import numpy as np

from .safe_command import SafeCommand


class CommandWatchdog:
    def __init__(
        self,
        robot,
        joints,
        timeout: float,
        gravity_by_hardware: bool = False,
        damping: float = 20.0,
        ramp: float = 0.05,
    ):
        if not timeout > 0:
            raise ValueError(f'command timeout must be > 0 s, got {timeout}')
        names = robot.get_joint_names()
        unknown = [j for j in joints if j not in names]
        if unknown:
            raise ValueError(f'joints {unknown} are not in the robot model')
        self.timeout = float(timeout)
        self.safe = SafeCommand(robot, gravity_by_hardware, damping, ramp)
        self._model_of_wire = np.array([names.index(j) for j in joints], dtype=int)
        self._last_cmd = np.zeros(len(names))  # model order; joints not commanded stay at 0
        self._last_t: float | None = None
        self.holding = False

    def on_command(self, t: float, command) -> bool:
        """
        Take a valid command that arrived at ``t`` (wire order).

        Returns True when it ends a hold.
        """
        self._last_cmd[self._model_of_wire] = command
        self._last_t = t
        ended = self.holding
        if ended:
            self.holding = False
            self.safe.reset()
        return ended

    def expired(self, t: float) -> bool:
        return self._last_t is None or t - self._last_t > self.timeout + 1e-12

    def silence(self, t: float) -> float | None:
        """Seconds since the last command (None before the first)."""
        return None if self._last_t is None else t - self._last_t

    def hold(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """
        Hold command (wire order) at ``t`` for model-order q, v.

        The first call starts the fade.
        """
        self.holding = True
        return self.safe.compute(t, self._last_cmd, q, v)[self._model_of_wire]
