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
The reference a position, velocity or impedance drive tracks: the QP's accelerations integrated.

A drive that takes positions or velocities does not take the torque the QP computed; it takes a
state to track. Each cycle the QP's joint accelerations a (at the measured state q, v) are
integrated over the control period dt from the reference's own last state (q_r, v_r), exactly for
a constant acceleration over the step:

    v_r' = v_r + dt a,        q_r' = q_r + dt v_r + dt^2 / 2 a

The reference is its own integral, not the measurement's (mc_rtc's integration, the one a stiff
servo tracks without a lag of one step), and it is leashed to the measured state: before each
step it is brought within ``position_leash`` [rad] and ``velocity_leash`` [rad/s] of (q, v). A
robot held back (a contact, a drive at its torque limit, a drive that lags) then never has a
reference running away from it, and the force a stiff drive exerts towards the reference stays
bounded by its stiffness times the leash. The first step, and the first after :meth:`reset`,
starts from the measured state.

Every joint limit holds on the reference, whatever the QP asked (its own limit constraints keep
it there; this is the last guard of what goes to the drive): |v_r| <= the velocity limit, q_r
within the position limits, and a reference on a position limit does not move further out (its
velocity towards it is zero). Limits that are not finite or not > 0 (continuous joints, a URDF
without velocity limits) do not bind.
"""

from __future__ import annotations

import numpy as np


class JointReference:
    """(q_r, v_r): the integrated, leashed, limited reference of n joints (see the module)."""

    def __init__(self, lower, upper, velocity_limit, position_leash: float = 0.05,
                 velocity_leash: float = 0.5):
        self.lower = np.array(lower, dtype=float)
        self.upper = np.array(upper, dtype=float)
        n = self.lower.size
        vmax = np.array(velocity_limit, dtype=float).reshape(-1)
        if self.upper.size != n or vmax.size != n:
            raise ValueError(f'limits of different sizes: {n}, {self.upper.size}, {vmax.size}')
        if np.any(self.lower > self.upper):
            raise ValueError('a lower position limit above its upper one')
        self.velocity_limit = np.where(np.isfinite(vmax) & (vmax > 0.0), vmax, np.inf)
        for what, value in (('position_leash', position_leash),
                            ('velocity_leash', velocity_leash)):
            if not (np.isfinite(value) and value > 0.0):
                raise ValueError(f'{what} must be finite and > 0, got {value}')
        self.position_leash = float(position_leash)
        self.velocity_leash = float(velocity_leash)
        self.position = np.zeros(n)
        self.velocity = np.zeros(n)
        self.started = False

    @classmethod
    def of_robot(cls, robot, position_leash: float = 0.05, velocity_leash: float = 0.5):
        """Make the reference of a RobotModel's joints, with the model's limits."""
        lower, upper = robot.get_joint_position_limits()
        return cls(lower, upper, robot.get_joint_velocity_limits(), position_leash,
                   velocity_leash)

    def reset(self) -> None:
        """Start again from the measured state at the next :meth:`advance`."""
        self.started = False

    def leash(self, q, v) -> None:
        """Bring the reference within the leash of the measured (q, v); start there if new."""
        q = np.asarray(q, dtype=float)
        v = np.asarray(v, dtype=float)
        if not self.started:
            self.position[:] = q
            self.velocity[:] = v
            self.started = True
            return
        np.clip(self.position, q - self.position_leash, q + self.position_leash,
                out=self.position)
        np.clip(self.velocity, v - self.velocity_leash, v + self.velocity_leash,
                out=self.velocity)

    def integrate(self, acceleration, dt: float) -> None:
        """Integrate ``acceleration`` over ``dt`` (constant over the step), then limit."""
        a = np.asarray(acceleration, dtype=float)
        self.position += dt * self.velocity + 0.5 * dt * dt * a
        self.velocity += dt * a
        self._limit()

    def advance(self, q, v, acceleration, dt: float) -> None:
        """One control period: :meth:`leash` to (q, v), then :meth:`integrate`."""
        self.leash(q, v)
        self.integrate(acceleration, dt)

    def hold(self) -> None:
        """Stop the reference where it is (velocity 0): the position a holding drive keeps."""
        self.velocity[:] = 0.0

    def _limit(self) -> None:
        np.clip(self.velocity, -self.velocity_limit, self.velocity_limit, out=self.velocity)
        below, above = self.position <= self.lower, self.position >= self.upper
        np.clip(self.position, self.lower, self.upper, out=self.position)
        self.velocity[below & (self.velocity < 0.0)] = 0.0
        self.velocity[above & (self.velocity > 0.0)] = 0.0
