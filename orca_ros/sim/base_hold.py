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
A floating base held where it was placed until its controller takes over (a test stand's crane).

Why: before its first command a free robot is held by its drives alone (gravity + damping of the
joints, :class:`orca_ros.safety.CommandWatchdog`). For an arm that is enough; a standing robot
also needs its feet's forces, which gravity compensation of the joints does not make: unheld,
its trunk sinks to the floor before its controller runs.

How: a fixed PyBullet constraint between the base (its centre of mass frame, where PyBullet puts
a body's base) and the world, at the base's pose when the hold starts. The joint rows of the
floating base's gravity vector are then exactly the torques that hold the legs still under a
fixed base, so the joints' hold keeps the posture too.

Release (:meth:`BaseHold.release`) lowers the constraint's force bound F_max linearly over
``ramp`` seconds of simulated time, from the robot's weight m g to 0, then removes it: while the
controller's feet take the load the crane gives way, at most m g (1 - s) at s of the ramp; a ramp
of 0 drops it at once. While held, F_max is ``HOLD_FACTOR`` m g (rigid against what the joints'
hold does). Time is the simulator's; :meth:`BaseHold.update` runs after each step (the server's
after-step callback).
"""

from __future__ import annotations

import pybullet

# the force bound while held, in weights: the hold gives way only to something violent
HOLD_FACTOR = 10.0


class ReleaseRamp:
    """A crane's release: the share of its bound left at simulated time t (1 until it starts)."""

    def __init__(self):
        self.start, self.ramp = None, 0.0

    def begin(self, t: float, ramp: float) -> None:
        """Start giving way at ``t``, over ``ramp`` seconds (0: at once)."""
        if not ramp >= 0.0:
            raise ValueError(f'release ramp must be >= 0 s, got {ramp}')
        self.start, self.ramp = float(t), float(ramp)

    def left(self, t: float) -> float:
        """Return 1 - s at ``t``, s the ramp's progress (0: the crane has let go)."""
        if self.start is None:
            return 1.0
        s = 1.0 if self.ramp <= 0.0 else (t - self.start) / self.ramp
        return min(max(1.0 - s, 0.0), 1.0)


class BaseHold:
    def __init__(self, server, model):
        """Hold ``model``'s base (floating) at its pose now; released by :meth:`release`."""
        if model.fixed_base:
            raise ValueError(f"model '{model.get_name()}' has a fixed base: nothing to hold")
        c = self._client = server.client
        body = model.body
        mass = sum(c.getDynamicsInfo(body, link)[0] for link in range(-1, c.getNumJoints(body)))
        self.weight = float(mass * abs(server.gravity[2]))
        com, orn = c.getBasePositionAndOrientation(body)
        self._id = c.createConstraint(
            body, -1, -1, -1, pybullet.JOINT_FIXED, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], com,
            childFrameOrientation=orn,
        )
        c.changeConstraint(self._id, maxForce=HOLD_FACTOR * self.weight)
        self.holding = True
        self._release = ReleaseRamp()
        server.execute_after_world_update(self.update)

    def release(self, t: float, ramp: float) -> None:
        """Start giving way at simulated time ``t``, over ``ramp`` seconds (0: at once)."""
        if not self.holding or self._release.start is not None:
            return
        self._release.begin(t, ramp)
        self.update(0, t, 0.0)

    def update(self, iteration: int, t: float, dt: float) -> None:
        """After a step: the force bound of the ramp at ``t``; removed once it reaches 0."""
        if not self.holding or self._release.start is None:
            return
        left = self._release.left(t)
        if left <= 0.0:
            self._client.removeConstraint(self._id)
            self.holding = False
            return
        self._client.changeConstraint(self._id, maxForce=self.weight * left)
