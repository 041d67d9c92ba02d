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
Joint torque, position, velocity and acceleration limits.

Position and velocity limits are turned into acceleration bounds. Velocities over a horizon h
(never shorter than the control period dt):
    v + h a in [v_min, v_max]              ->  a in 1/h [v_min - v, v_max - v]
Positions, *viable* in discrete time (after Del Prete, RA-L 2018), for the step the robot takes
under a constant acceleration over dt (q' = q + dt v + dt^2/2 a, v' = v + dt a), with A the
deceleration the joint can always produce (``set_max_acceleration``):
* the next position stays within the limits: a <= 2 (q_max - q - dt v) / dt^2 (and below);
* the next state can still stop before the limit at deceleration A: v'^2 <= 2 A (q_max - q') when
  v' > 0, a quadratic inequality in a (and mirrored at q_min);
* a smoother approach over the horizon h, q + h v + h^2/2 a <= q_max, only as far as it asks for
  no more than A.
A state that satisfies the viability condition keeps a = -A admissible for both the next step and
the one after (so the bounds are never empty and a braking joint never needs more than A), and
the one-step bound is exact: no excursion at all. A state that does not (started close to a limit,
pushed) brakes at A; only the one-step bound may then ask for more. Position and velocity limits
default to the URDF's values; torque limits to the URDF's efforts.
"""

from __future__ import annotations

import numpy as np

from .generic_constraint import _limit_vector, GenericConstraint, JointBoxConstraint


class _SymmetricLimitsMixin:
    def set_limits(self, lower, upper) -> None:
        n = (
            self.robot.get_nr_of_degrees_of_freedom()
            if self.robot is not None
            else np.asarray(lower).size
        )
        lo = _limit_vector(lower, n, 'lower limit', self.name)
        hi = _limit_vector(upper, n, 'upper limit', self.name)
        if np.any(lo > hi):
            raise ValueError(
                f"constraint '{self.name}': lower limit above upper limit at joints "
                f'{np.flatnonzero(lo > hi).tolist()}'
            )
        self._limits = (lo, hi)

    def get_limits(self):
        if self._limits is None:
            return None
        return self._limits[0].copy(), self._limits[1].copy()

    def _default_limits(self):
        return None

    def set_robot_model(self, robot) -> None:
        super().set_robot_model(robot)
        if self._limits is None:
            self._limits = self._default_limits()


class JointTorqueLimitConstraint(_SymmetricLimitsMixin, GenericConstraint):
    """tau_min <= M_a nu_dot + n_a - J_a^T w <= tau_max."""

    def __init__(self, name: str):
        super().__init__(name)
        self._limits = None

    def rows(self) -> int:
        return self.layout.ndof

    def _default_limits(self):
        e = self.robot.get_joint_torque_limits()
        e = np.where((e > 0) & np.isfinite(e), e, np.inf)
        return -e, e

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        lay = self.layout
        self.C[:] = lay.T
        lo, hi = self._limits
        np.subtract(lo, lay.t0, out=self.lb)
        np.subtract(hi, lay.t0, out=self.ub)


class JointPositionLimitConstraint(_SymmetricLimitsMixin, JointBoxConstraint):
    def __init__(self, name: str, horizon: float = 0.05, max_acceleration: float = 5.0):
        super().__init__(name)
        self._limits = None
        self.set_horizon(horizon)
        self.set_max_acceleration(max_acceleration)

    def set_horizon(self, horizon: float) -> None:
        if not horizon > 0.0:
            raise ValueError(f"constraint '{self.name}': prediction horizon must be > 0 s")
        self.horizon = float(horizon)

    def set_max_acceleration(self, value) -> None:
        """
        Deceleration A every joint can always produce [rad/s^2 or m/s^2], scalar or per joint.

        The viability bound keeps each joint able to stop at A before its limits; A must be within
        what the torque limits allow in every posture, or braking may need more torque than there
        is.
        """
        a = np.asarray(value, dtype=float)
        if not (np.all(np.isfinite(a)) and np.all(a > 0.0)):
            raise ValueError(
                f"constraint '{self.name}': max acceleration must be finite and > 0, got {value}"
            )
        self.max_acceleration = a

    def _default_limits(self):
        return self.robot.get_joint_position_limits()

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        robot = self.robot
        q, v = robot._q, robot._v
        lo, hi = self._limits
        acc = self.max_acceleration
        with np.errstate(invalid='ignore'):  # infinite limits give infinite bounds
            self.ub[:] = _viable_upper(hi - q, v, dt, acc, max(self.horizon, dt))
            self.lb[:] = -_viable_upper(q - lo, -v, dt, acc, max(self.horizon, dt))


def _viable_upper(room, v, dt, acc, h):
    """
    Return the largest admissible acceleration towards an upper limit ``room`` away.

    ``room`` = q_max - q (>= 0 when within the limit), ``v`` the velocity towards it.
    """
    step = 2.0 * (room - dt * v) / (dt * dt)  # next position within the limit
    # v'^2 <= 2 A (room - dt v - dt^2/2 a) with v' = v + dt a >= 0:
    # dt^2 a^2 + (2 v dt + A dt^2) a + v^2 - 2 A (room - dt v) <= 0
    b = 2.0 * v * dt + acc * dt * dt
    c = v * v - 2.0 * acc * (room - dt * v)
    disc = b * b - 4.0 * dt * dt * c
    root = (-b + np.sqrt(np.maximum(disc, 0.0))) / (2.0 * dt * dt)
    stop = -v / dt  # accelerations at or below this end the step at rest or moving away
    viable = np.where(disc >= 0.0, np.maximum(root, stop), stop)
    smooth = 2.0 * (room - h * v) / (h * h)
    # neither asks for more than A: in a viable state the viability bound never does; in a state
    # that is not (a start close to the limit, a push) it brakes at A rather than demanding a stop
    # within one step, which the torque limits may not allow; only the next position is exact
    out = np.minimum(step, np.maximum(np.minimum(viable, smooth), -acc))
    return np.where(np.isfinite(room), out, np.inf)


class JointVelocityLimitConstraint(_SymmetricLimitsMixin, JointBoxConstraint):
    def __init__(self, name: str, horizon: float = 0.01):
        super().__init__(name)
        self._limits = None
        self.set_horizon(horizon)

    def set_horizon(self, horizon: float) -> None:
        """
        Time to reach the limit.

        Never shorter than the control period; a one-period horizon makes the bound bang-bang (full
        stop in one cycle) and often incompatible with the torque limits.
        """
        if not horizon > 0.0:
            raise ValueError(f"constraint '{self.name}': horizon must be > 0 s")
        self.horizon = float(horizon)

    def _default_limits(self):
        v = self.robot.get_joint_velocity_limits()
        v = np.where((v > 0) & np.isfinite(v), v, np.inf)
        return -v, v

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        h = max(self.horizon, dt)
        v = self.robot._v
        lo, hi = self._limits
        np.multiply(lo - v, 1.0 / h, out=self.lb)
        np.multiply(hi - v, 1.0 / h, out=self.ub)


class JointAccelerationLimitConstraint(_SymmetricLimitsMixin, JointBoxConstraint):
    """qdd_min <= q_ddot <= qdd_max (no URDF field: unbounded until set_limits is called)."""

    hard = True

    def __init__(self, name: str):
        super().__init__(name)
        self._limits = None

    def _default_limits(self):
        n = self.robot.get_nr_of_degrees_of_freedom()
        return np.full(n, -np.inf), np.full(n, np.inf)

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        self.lb[:], self.ub[:] = self._limits
