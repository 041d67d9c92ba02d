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
A floating base's twist from its poses, for odometry that carries none: filtered differences.

Linear: (p_k - p_{k-1}) / dt; angular: R_{k-1} log3(R_{k-1}^T R_k) / dt (the rotation between the
two readings, in world axes; exact for a constant angular velocity). Both low-passed as the joint
velocities of :class:`~orca_ros.robot.velocity_estimator.VelocityEstimator` are (first order at
``cutoff`` Hz, the same handling of the first reading, of a repeated instant and of gaps), so a
base and its joints lag alike. Returns [linear; angular] in world axes, the base origin's, as
``RobotModel.set_robot_state`` takes them.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin


class BaseTwistEstimator:
    def __init__(self, cutoff: float = 100.0, max_gap: float = 0.1):
        if not (math.isfinite(cutoff) and cutoff > 0.0):
            raise ValueError(f'twist estimate cutoff must be finite and > 0, got {cutoff}')
        self.tau = 1.0 / (2.0 * math.pi * float(cutoff))
        self.max_gap = float(max_gap)
        self.twist = np.zeros(6)
        self._T = np.eye(4)
        self._t: float | None = None
        self._raw = np.zeros(6)

    def update(self, T: np.ndarray, t: float) -> np.ndarray:
        """Take the base pose ``T`` (4x4, world) read at ``t`` [s]; return the estimate."""
        prev = self._t
        if prev is not None and prev - self.max_gap <= t <= prev:
            return self.twist  # the same instant again
        if prev is None or abs(t - prev) > self.max_gap:
            self.twist[:] = 0.0
        else:
            dt = t - prev
            R0 = self._T[:3, :3]
            self._raw[:3] = (T[:3, 3] - self._T[:3, 3]) / dt
            self._raw[3:] = R0 @ pin.log3(R0.T @ T[:3, :3]) / dt
            self.twist += (1.0 - math.exp(-dt / self.tau)) * (self._raw - self.twist)
        self._T[:] = T
        self._t = t
        return self.twist
