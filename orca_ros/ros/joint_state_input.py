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
Joint states off the wire -> model-order positions and velocities, after plausibility checks.

A message is rejected as a whole, with a cause (a short key for throttled logging) and a line
naming what is wrong: missing or duplicate joint names, array sizes, NaN/infinite values, a
position outside the URDF limits by more than ``position_margin``, a velocity beyond
``velocity_factor`` times the URDF velocity limit (or ``max_velocity`` where the URDF gives none).
Absurd finite values (1e300) fail the limit checks like any other implausible reading, without
arithmetic that could overflow. The positions of the joints locked in the model (another
controller's, e.g. a gripper's) are read and checked too, into ``locked_positions``; other extra
joints are ignored. A message without velocities (``JointState`` allows empty arrays: a driver
that measures positions only) has them estimated from the positions, by filtered differences over
the messages' stamps (:class:`~orca_ros.robot.velocity_estimator.VelocityEstimator`, 100 Hz);
``estimating`` says so, for the node's log line. No ROS here: the node hands over the message's
fields.
"""

from __future__ import annotations

import time

import numpy as np

from ..robot.velocity_estimator import VelocityEstimator

# |q| bound for joints without finite URDF position limits (rad or m): any real reading is below
_UNLIMITED = 1e4


class StateRejected(ValueError):
    def __init__(self, cause: str, text: str):
        super().__init__(text)
        self.cause = cause


class JointStateInput:
    def __init__(
        self,
        robot,
        joints,
        wire_of_model,
        position_margin: float = 0.1,
        velocity_factor: float = 3.0,
        max_velocity: float = 100.0,
    ):
        self.joints = list(joints)  # wire order
        self.locked = robot.get_locked_joint_names()  # read, checked, never commanded
        self._wire_of_model = np.asarray(wire_of_model, dtype=int)
        lo, hi = robot.get_joint_position_limits()  # model order
        vel = robot.get_joint_velocity_limits()
        to_wire = np.empty(len(self.joints), dtype=int)
        to_wire[self._wire_of_model] = np.arange(len(self.joints))
        lo, hi, vel = lo[to_wire], hi[to_wire], vel[to_wire]  # wire order, as the message values
        locked_lo, locked_hi = robot.get_locked_joint_position_limits()
        lo, hi = np.concatenate((lo, locked_lo)), np.concatenate((hi, locked_hi))
        self.locked_positions = np.zeros(len(self.locked))
        limited = (
            np.isfinite(lo) & np.isfinite(hi) & (hi > lo) & (np.abs(lo) < 1e9) & (np.abs(hi) < 1e9)
        )
        margin = float(position_margin)
        self.lower = np.where(limited, lo - margin, -_UNLIMITED)
        self.upper = np.where(limited, hi + margin, _UNLIMITED)
        self.margin = margin
        self._names = self.joints + self.locked
        has_v = np.isfinite(vel) & (vel > 0)
        self.max_speed = np.where(
            has_v, float(velocity_factor) * np.where(has_v, vel, 0.0), float(max_velocity)
        )
        self._names_key: tuple | None = None
        self._pick: np.ndarray | None = None
        self.estimator = VelocityEstimator(len(self.joints))
        self.estimating = False  # the last message had no velocities: they were estimated

    def _indices(self, names) -> np.ndarray:
        key = tuple(names)
        if key == self._names_key:
            return self._pick
        if len(set(key)) != len(key):
            seen, dup = set(), []
            for n in key:
                if n in seen and n not in dup:
                    dup.append(n)
                seen.add(n)
            raise StateRejected(
                'state:duplicates', f'joint_states rejected: duplicate joint names {dup}'
            )
        where = {n: i for i, n in enumerate(key)}
        missing = [j for j in self._names if j not in where]
        if missing:
            raise StateRejected(
                'state:missing', f'joint_states rejected: missing joints {missing}'
            )
        self._pick = np.array([where[j] for j in self._names], dtype=int)
        self._names_key = key
        return self._pick

    def read(self, names, position, velocity, q_out: np.ndarray, v_out: np.ndarray,
             stamp: float = 0.0) -> None:
        """
        Check a message and write model-order q, v into ``q_out``, ``v_out``.

        ``stamp``: the message's time [s] (0: unstamped, the time of reading is used), for the
        velocities estimated when the message has none. Raises StateRejected.
        """
        pick = self._indices(names)
        n = len(names)
        estimate = len(velocity) == 0 and n > 0
        if len(position) != n or (len(velocity) != n and not estimate):
            raise StateRejected(
                'state:sizes',
                f'joint_states rejected: {len(position)} positions and '
                f'{len(velocity)} velocities for {n} names',
            )
        pos = np.asarray(position, dtype=float)[pick]
        n_cmd = len(self.joints)
        vel = (np.zeros(n_cmd) if estimate
               else np.asarray(velocity, dtype=float)[pick[:n_cmd]])
        if not (np.isfinite(pos).all() and np.isfinite(vel).all()):
            bad_v = np.zeros(pos.size, dtype=bool)
            bad_v[:vel.size] = ~np.isfinite(vel)
            bad = [self._names[i] for i in np.flatnonzero(~np.isfinite(pos) | bad_v)]
            raise StateRejected(
                'state:nan', f'joint_states rejected: NaN or infinite position/velocity of {bad}'
            )
        out = (pos < self.lower) | (pos > self.upper)
        if out.any():
            i = int(np.flatnonzero(out)[0])
            raise StateRejected(
                'state:limits',
                (
                    f'joint_states rejected: {self._names[i]} position {pos[i]:.4g} outside its '
                    'limits '
                    f'[{self.lower[i] + self.margin:.4g}, {self.upper[i] - self.margin:.4g}] by '
                    'more than the '
                    f'{self.margin:g} margin'
                    if self.upper[i] < _UNLIMITED
                    else f'joint_states rejected: {self._names[i]} position {pos[i]:.4g} is not a '
                         'plausible reading'
                ),
            )
        self.estimating = estimate
        if estimate:  # positions checked: differentiate them
            vel = self.estimator.update(pos[:n_cmd], stamp if stamp > 0.0 else time.monotonic())
        fast = np.abs(vel) > self.max_speed
        if fast.any():
            i = int(np.flatnonzero(fast)[0])
            raise StateRejected(
                'state:velocity',
                f'joint_states rejected: {self.joints[i]} velocity {vel[i]:.4g} '
                f'beyond the plausible {self.max_speed[i]:.4g}',
            )
        q_out[:] = pos[:n_cmd][self._wire_of_model]
        v_out[:] = vel[self._wire_of_model]
        self.locked_positions[:] = pos[n_cmd:]
