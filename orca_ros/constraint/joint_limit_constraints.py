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
Positions: bounds *viable* in discrete time (after Del Prete, RA-L 2018; see
:mod:`.viable_bound`): the next position is within the limits exactly, and every joint can still
stop before them at the deceleration ``set_max_acceleration``. Position and velocity limits
default to the URDF's values; torque limits to the URDF's efforts.
"""

from __future__ import annotations

import numpy as np

from .generic_constraint import _limit_vector, GenericConstraint, JointBoxConstraint
from .viable_bound import ViableBound


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
        self.limits = (lo, hi)

    def get_limits(self):
        if self.limits is None:
            return None
        return self.limits[0].copy(), self.limits[1].copy()

    def _default_limits(self):
        return None

    def set_robot_model(self, robot) -> None:
        super().set_robot_model(robot)
        if self.limits is None:
            self.limits = self._default_limits()


class JointTorqueLimitConstraint(_SymmetricLimitsMixin, GenericConstraint):
    """tau_min <= M_a nu_dot + n_a - J_a^T w <= tau_max."""

    def __init__(self, name: str):
        super().__init__(name)
        self.limits = None

    def rows(self) -> int:
        return self.layout.ndof

    def _default_limits(self):
        e = self.robot.get_joint_torque_limits()
        e = np.where((e > 0) & np.isfinite(e), e, np.inf)
        return -e, e

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        lay = self.layout
        self.C[:] = lay.T
        lo, hi = self.limits
        np.subtract(lo, lay.t0, out=self.lb)
        np.subtract(hi, lay.t0, out=self.ub)


class JointPositionLimitConstraint(_SymmetricLimitsMixin, JointBoxConstraint):
    def __init__(self, name: str, horizon: float = 0.05, max_acceleration: float = 5.0):
        super().__init__(name)
        self.limits = None
        self._bound = None  # ViableBound of both sides, made at the first update after a change
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
        self._bound = None

    def _default_limits(self):
        return self.robot.get_joint_position_limits()

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        q, v = self.robot.buffers.q, self.robot.buffers.v
        n = q.size
        vb = self._bound
        if vb is None or vb.size != 2 * n:
            # both sides of every joint in one pass: [upper limits; lower limits, mirrored]
            vb = self._bound = ViableBound(2 * n)
            vb.set_acceleration(np.concatenate([np.broadcast_to(self.max_acceleration, n)] * 2))
            self._room, self._vel, self._out = np.zeros(2 * n), np.zeros(2 * n), np.zeros(2 * n)
        lo, hi = self.limits
        room, vel, out = self._room, self._vel, self._out
        np.subtract(hi, q, out=room[:n])
        np.subtract(q, lo, out=room[n:])
        vel[:n] = v
        np.negative(v, out=vel[n:])
        vb.upper(room, vel, dt, max(self.horizon, dt), out)
        self.ub[:] = out[:n]
        np.negative(out[n:], out=self.lb)


class JointVelocityLimitConstraint(_SymmetricLimitsMixin, JointBoxConstraint):
    def __init__(self, name: str, horizon: float = 0.01):
        super().__init__(name)
        self.limits = None
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
        v = self.robot.buffers.v
        lo, hi = self.limits
        np.multiply(lo - v, 1.0 / h, out=self.lb)
        np.multiply(hi - v, 1.0 / h, out=self.ub)


class JointAccelerationLimitConstraint(_SymmetricLimitsMixin, JointBoxConstraint):
    """qdd_min <= q_ddot <= qdd_max (no URDF field: unbounded until set_limits is called)."""

    hard = True

    def __init__(self, name: str):
        super().__init__(name)
        self.limits = None

    def _default_limits(self):
        n = self.robot.get_nr_of_degrees_of_freedom()
        return np.full(n, -np.inf), np.full(n, np.inf)

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        self.lb[:], self.ub[:] = self.limits
