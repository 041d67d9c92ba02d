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
Targets reached along jerk-limited trajectories.

With Ruckig, the online generator MoveIt 2 uses (no ROS here).

A target handed straight to a PD servo is a step: the first cycle demands kp * distance of
acceleration (a 30 cm step on the arm: 120 m/s^2, torques at their limits). Instead, a new target
starts a time-optimal trajectory from the current reference state (position, velocity,
acceleration: a target changed mid-motion continues smoothly) within velocity, acceleration and
jerk limits; each cycle samples it at the controller's clock and the servo gets position, velocity
and acceleration (feed-forward). After the end the target is held.

* :class:`JointTrajectory`: N joints, per-joint limits, time-synchronised.
* :class:`CartesianTrajectory`: the position along x, y, z with limits scaled by the direction of
  travel (phase synchronised: a straight line at most ``max_velocity`` fast in Euclidean norm from
  rest), the orientation as one rotation angle about the fixed axis from the start to the target
  orientation (angular velocity at the start projected on that axis).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..utils.optional_import import optional_import


def _ruckig():
    # ros-jazzy-ruckig is the C++ library only: the Python bindings come from pip
    return optional_import(
        'ruckig', 'target trajectories', 'or tasks.<name>.trajectory.enabled: false'
    )


def checked_limits(value, n: int, what: str) -> np.ndarray:
    v = np.asarray(value, dtype=float).reshape(-1)
    if v.size == 1:
        v = np.full(n, float(v[0]))
    if v.shape != (n,) or not (np.isfinite(v).all() and (v > 0).all()):
        raise ValueError(
            f'trajectory {what}: expected 1 or {n} positive finite values, got {value!r}'
        )
    return v


# a state this close to its target (m or rad, per s, per s^2) is at it: no trajectory is planned
_AT_TARGET = 1e-9


class _Profile:
    """One Ruckig trajectory over n DoF, started at a time stamp and sampled by absolute time."""

    def __init__(self, n: int, synchronization: str = 'Time'):
        rk = self._rk = _ruckig()
        self.n = n
        self._otg = rk.Ruckig(n)
        self._inp = rk.InputParameter(n)
        self._inp.synchronization = getattr(rk.Synchronization, synchronization)
        self._traj = rk.Trajectory(n)
        self.t0: float | None = None
        self._rest = None  # the target, when the state already is there (no trajectory)

    def plan(self, t0, p, v, a, target, vmax, amax, jmax) -> float:
        inp = self._inp
        inp.current_position, inp.current_velocity, inp.current_acceleration = (
            list(p),
            list(v),
            list(a),
        )
        inp.target_position = list(target)
        inp.target_velocity = inp.target_acceleration = [0.0] * self.n
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(vmax), list(amax), list(jmax)
        self._rest = None
        try:
            res = self._otg.calculate(inp, self._traj)
        except self._rk.RuckigError as exc:
            res, why = None, str(exc).strip().splitlines()[0]
        ok = res in (self._rk.Result.Working, self._rk.Result.Finished)
        if not ok:
            # a state already at the target but for rounding (1e-15 m away, 1e-27 m/s) makes
            # Ruckig fail, in any synchronization: no trajectory, the target held
            dust = max(np.abs(np.subtract(target, p)).max(), np.abs(v).max(), np.abs(a).max())
            if not dust <= _AT_TARGET:  # NaN included
                raise ValueError(
                    f'no trajectory to this target (Ruckig: {why if res is None else res.name})'
                )
            self._rest = np.array(target, dtype=float)
        self.t0 = float(t0)
        return self.duration

    @property
    def duration(self) -> float:
        return 0.0 if self._rest is not None else self._traj.duration

    def sample(self, t: float):
        if self._rest is not None:
            return self._rest.copy(), np.zeros(self.n), np.zeros(self.n)
        tau = min(max(t - self.t0, 0.0), self._traj.duration)
        p, v, a = self._traj.at_time(tau)
        return np.asarray(p), np.asarray(v), np.asarray(a)

    def done(self, t: float) -> bool:
        return self.t0 is None or t - self.t0 >= self.duration


class JointTrajectory:
    def __init__(self, n: int, max_velocity, max_acceleration, max_jerk):
        self.vmax = checked_limits(max_velocity, n, 'max_velocity')
        self.amax = checked_limits(max_acceleration, n, 'max_acceleration')
        self.jmax = checked_limits(max_jerk, n, 'max_jerk')
        self._p = _Profile(n)
        self.active = False

    def start(self, t, position, velocity, acceleration, target) -> float:
        d = self._p.plan(
            t, position, velocity, acceleration, target, self.vmax, self.amax, self.jmax
        )
        self.active = True
        return d

    def sample(self, t: float):
        """(q, qd, qdd) at time t (the target, at rest, after the end)."""
        return self._p.sample(t)

    def finished(self, t: float) -> bool:
        return self._p.done(t)


class CartesianTrajectory:
    def __init__(self, max_velocity, max_acceleration, max_jerk):
        """Limits as [linear, angular] pairs (m/s, rad/s; m/s^2, rad/s^2; m/s^3, rad/s^3)."""
        self.vmax = checked_limits(max_velocity, 2, 'max_velocity [linear, angular]')
        self.amax = checked_limits(max_acceleration, 2, 'max_acceleration [linear, angular]')
        self.jmax = checked_limits(max_jerk, 2, 'max_jerk [linear, angular]')
        self._lin = _Profile(3, 'Phase')
        self._ang = _Profile(1)
        self._R0 = np.eye(3)
        self._axis = np.array([0.0, 0.0, 1.0])
        self.active = False
        self._out = np.eye(4)

    def start(self, t, pose, twist, acceleration, target) -> float:
        """
        From ``pose`` (4x4).

        ``twist`` and ``acceleration`` ([linear, angular], base frame) to ``target``.
        """
        pose, target = np.asarray(pose, dtype=float), np.asarray(target, dtype=float)
        twist, acceleration = np.asarray(twist, dtype=float), np.asarray(acceleration, dtype=float)
        d = target[:3, 3] - pose[:3, 3]
        dist = float(np.linalg.norm(d))
        # per-axis limits in proportion to the direction: from rest, a straight line within the
        # norm limits
        share = np.abs(d) / dist if dist > 1e-9 else np.full(3, 1.0 / np.sqrt(3.0))
        share = np.maximum(share, 1e-3)
        lin = self._lin.plan(
            t,
            pose[:3, 3],
            twist[:3],
            acceleration[:3],
            target[:3, 3],
            self.vmax[0] * share,
            self.amax[0] * share,
            self.jmax[0] * share,
        )
        self._R0 = pose[:3, :3].copy()
        rotvec = pin.log3(self._R0.T @ target[:3, :3])  # in the start frame
        angle = float(np.linalg.norm(rotvec))
        self._axis = rotvec / angle if angle > 1e-12 else np.array([0.0, 0.0, 1.0])
        axis_base = self._R0 @ self._axis
        ang = self._ang.plan(
            t,
            [0.0],
            [float(axis_base @ twist[3:])],
            [float(axis_base @ acceleration[3:])],
            [angle],
            self.vmax[1:],
            self.amax[1:],
            self.jmax[1:],
        )
        self.active = True
        return max(lin, ang)

    def sample(self, t: float):
        """(pose 4x4, twist 6, acceleration 6) at time t, base frame, [linear; angular]."""
        p, v, a = self._lin.sample(t)
        th, thd, thdd = self._ang.sample(t)
        out = self._out
        out[:3, :3] = self._R0 @ pin.exp3(self._axis * float(th[0]))
        out[:3, 3] = p
        w = self._R0 @ self._axis
        return (
            out.copy(),
            np.concatenate((v, w * float(thd[0]))),
            np.concatenate((a, w * float(thdd[0]))),
        )

    def finished(self, t: float) -> bool:
        return self._lin.done(t) and self._ang.done(t)
