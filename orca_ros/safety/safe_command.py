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
The command sent when the controller cannot be trusted (stale state, QP failure, hold, shutdown).

hold(q, v) = g(q) - M(q) k_d v   (g omitted when the drives compensate gravity themselves), clipped
to the torque limits. The damping is an acceleration gain (1/s) weighted by the mass matrix, so
every joint gets the same damping time constant: a plain Nm s/rad gain strong enough for the
shoulder makes a light wrist joint unstable at a 1 ms control period (the last joint of the arm
spun). When trouble starts, the last good command fades linearly into the hold command over
``ramp`` seconds, so the torques never step. For a floating-base robot g(q) is the actuated part of
the free robot's gravity torques (what holds its limbs, not what would keep it standing: no safe
command can do that alone).

Two users: the controller node (:meth:`compute` at the state it measured, set on the robot here)
and the core's :class:`~orca_ros.optim.controller.Controller`, whose failed cycle's command it is
(:meth:`compute_at_state`: the state the cycle ran at, its terms read as they are, not set again).
"""

from __future__ import annotations

import numpy as np


class SafeCommand:
    def __init__(
        self, robot, gravity_by_hardware: bool = False, damping: float = 10.0, ramp: float = 0.2
    ):
        self.robot = robot
        self.gravity_by_hardware = bool(gravity_by_hardware)
        self.damping = float(damping)
        self.ramp = float(ramp)
        lim = robot.get_joint_torque_limits()
        self.limit = np.where((lim > 0) & np.isfinite(lim), lim, np.inf)
        self._lower = -self.limit
        self._start: float | None = None
        n = robot.get_nr_of_degrees_of_freedom()
        self._nb = robot.get_configuration_space_dimension() - n
        self._from = np.zeros(n)
        self._zeros = np.zeros(n)
        self._tau = np.zeros(n)  # the hold's buffer (a spell calls it every cycle)
        self.active = False

    def hold(self, q: np.ndarray, v: np.ndarray | None) -> np.ndarray:
        """Set the state (q, v; v None: at rest, undamped) on the robot and return its hold."""
        r, nb = self.robot, self._nb
        vs = self._zeros if v is None else v
        if nb:  # keep the last base pose; a floating base gets no support torque
            r.set_robot_state(r.get_world_to_base_transform(), q, np.zeros(6), vs, r.get_gravity())
        else:
            r.set_robot_state(q, vs)
        return self._hold(v)

    def hold_at_state(self) -> np.ndarray:
        """
        Return the hold at the robot's current state, damping its current joint velocities.

        The state is not set again: g(q) and M(q) are the robot's terms of that state, computed
        once for it (a controller's cycle has already set it).
        """
        return self._hold(self.robot.get_generalized_velocity()[self._nb:])

    def _hold(self, v: np.ndarray | None) -> np.ndarray:
        """g(q) - M(q) k_d v of the actuated joints at the robot's state, clipped (see module)."""
        r, nb = self.robot, self._nb
        tau = self._tau
        if self.gravity_by_hardware:
            tau.fill(0.0)
        else:
            tau[:] = r.get_generalized_gravity_torques()[nb:]
        if v is not None:
            tau -= self.damping * (r.get_mass_matrix()[nb:, nb:] @ v)
        out = np.maximum(tau, self._lower)  # a new array: the caller may keep it
        return np.minimum(out, self.limit, out=out)

    def compute(
        self, t: float, last_command: np.ndarray, q: np.ndarray, v: np.ndarray | None
    ) -> np.ndarray:
        """Command at time t; the fade starts at the first call after :meth:`reset`."""
        self._begin(t, last_command)
        return self._fade(t, self.hold(q, v))

    def compute_at_state(self, t: float, last_command: np.ndarray) -> np.ndarray:
        """:meth:`compute` at the robot's current state (:meth:`hold_at_state`)."""
        self._begin(t, last_command)
        return self._fade(t, self.hold_at_state())

    def _begin(self, t: float, last_command: np.ndarray) -> None:
        """Start the fade from ``last_command`` at t, unless one is running."""
        if not self.active:
            self.active = True
            self._start = t
            self._from = np.array(last_command, dtype=float)

    def _fade(self, t: float, hold: np.ndarray) -> np.ndarray:
        """(1 - a) last + a hold, a = (t - start) / ramp in [0, 1]; non-finite parts: the hold."""
        a = 1.0 if self.ramp <= 0 else min(1.0, max(0.0, (t - self._start) / self.ramp))
        if a >= 1.0:
            return hold
        out = (1.0 - a) * self._from + a * hold
        return np.where(np.isfinite(out), out, hold)

    def reset(self) -> None:
        self.active = False
        self._start = None
