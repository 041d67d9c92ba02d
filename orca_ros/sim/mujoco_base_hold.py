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
A floating base held where it was placed until its controller takes over, in the MuJoCo world.

:class:`~orca_ros.sim.BaseHold`'s contract (why: see there). How: MuJoCo's welds have no force
bound, so the crane is a stiff wrench on the base link: the robot's weight carried, plus a
critically damped spring to the pose the hold started at (``HOLD_HZ``, on the robot's mass and its
rotational inertia at the base: each axis its own, so that no axis is damped past what an explicit
step allows), bounded by ``HOLD_FACTOR`` weights (a torque of as many weights
times ``LEVER``). Release (:meth:`MujocoBaseHold.release`) lowers both bounds linearly over
``ramp`` seconds of simulated time, from the weight (and its torque) to 0, then lets go:
at s of the ramp the crane carries at most m g (1 - s). :meth:`MujocoBaseHold.update` runs after
each step (the world's after-step callback) and sets the wrench of the next.
"""

from __future__ import annotations

import numpy as np

from .base_hold import HOLD_FACTOR, ReleaseRamp
from ..math.rotations import orientation_error

#: the crane's spring [Hz]: stiff against what the joints' hold does, stable at 1 ms steps
HOLD_HZ = 20.0
#: the crane's torque bound, in weights times this lever [m]
LEVER = 1.0


def _bounded(x: np.ndarray, bound: float) -> np.ndarray:
    n = float(np.linalg.norm(x))
    return x if n <= bound else x * (bound / n)


class MujocoBaseHold:
    def __init__(self, server, model):
        """Hold ``model``'s base (floating) at its pose now; released by :meth:`release`."""
        if model.fixed_base:
            raise ValueError(f"model '{model.get_name()}' has a fixed base: nothing to hold")
        self._model = model
        mass, inertia = model.get_base_inertia()
        self._g = np.asarray(server.gravity, dtype=float)
        self.weight = float(mass * np.linalg.norm(self._g))
        self._mass = mass
        self._inertia = inertia  # base axes
        self._pose = model.get_world_to_base_transform()
        self.holding = True
        self._release = ReleaseRamp()
        self._scale = HOLD_FACTOR
        self.update(0, server.get_time(), 0.0)
        server.execute_after_world_update(self.update)

    def release(self, t: float, ramp: float) -> None:
        """Start giving way at simulated time ``t``, over ``ramp`` seconds (0: at once)."""
        if not self.holding or self._release.start is not None:
            return
        self._release.begin(t, ramp)
        self.update(0, t, 0.0)

    def update(self, iteration: int, t: float, dt: float) -> None:
        """After a step: the crane's wrench for the next, bounded as the ramp is at ``t``."""
        if not self.holding:
            return
        if self._release.start is not None:
            self._scale = self._release.left(t)
            if self._scale <= 0.0:
                self._model.set_base_wrench(np.zeros(3), np.zeros(3))
                self.holding = False
                return
        w = 2.0 * np.pi * HOLD_HZ
        T = self._model.get_world_to_base_transform()
        twist = self._model.get_base_velocity()
        force = self._mass * (-self._g + w * w * (self._pose[:3, 3] - T[:3, 3])
                              - 2.0 * w * twist[:3])
        turn = orientation_error(self._pose[:3, :3], T[:3, :3])
        R = T[:3, :3]
        torque = R @ self._inertia @ R.T @ (w * w * turn - 2.0 * w * twist[3:])
        bound = self._scale * self.weight
        self._model.set_base_wrench(_bounded(force, bound), _bounded(torque, bound * LEVER))
