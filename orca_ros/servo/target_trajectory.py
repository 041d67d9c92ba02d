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

The reference never leads the measured state by more than a bound (:meth:`follow`): the distance
the reference covers in ``max_lead`` seconds [0.2 s] at its velocity limit (5 cm and 0.2 rad with
the Cartesian defaults, 0.2 s of half the URDF velocity for joints). A servo that follows tracks
within millimetres (the shipped arm: a few mm at most at 0.25 m/s, kp 400 with feed-forward), far
inside it; a servo that cannot (a target out of reach, a constraint in the way) would leave the
reference running on towards the target, and the next target would start from there, metres away
and at full speed. Instead the part (position, orientation; or joint) beyond the bound restarts
from the measured position, moved the bound towards the old reference, at rest (no velocity, no
acceleration), to the same target; the rest goes on as it was. The servo then pulls with its gain
times the bound and damps the robot's own velocity: a steady pull, no jolt back to nothing and no
sawtooth (from exactly the measured state the pull would drop to zero at each restart), and no
reference dragged along by a robot moving away (from the measured velocity, the servo's damping
would vanish: seen through the nodes, the stretched arm wandered off by a metre). ``following``
tells whether the servo follows (no restart in the last ``max_lead`` seconds, the lead at most half
the bound); when it does not, a new target is best started from the measured state, not from the
reference on the leash ahead of it.
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
# the reference leads the measured state by at most what it covers in this time at its velocity
# limit (see the module)
MAX_LEAD = 0.2


def leashed(reference: np.ndarray, measured: np.ndarray, bound) -> np.ndarray | None:
    """
    Pull ``reference`` back to ``bound`` from ``measured`` (vectors); None when within it.

    Per component with a vector ``bound`` (joints), in Euclidean norm with a scalar one.
    """
    d = reference - measured
    if np.ndim(bound) == 0:
        n = float(np.linalg.norm(d))
        return None if not n > bound else measured + d * (bound / n)
    if not (np.abs(d) > bound).any():
        return None
    return measured + np.clip(d, -bound, bound)


class _Profile:
    """One Ruckig trajectory over n DoF, started at a time stamp and sampled by absolute time."""

    def __init__(self, n: int, synchronization: str = 'Time'):
        rk = self._rk = _ruckig()
        self.n = n
        self._otg = rk.Ruckig(n)
        self._inp = rk.InputParameter(n)
        self.synchronization = getattr(rk.Synchronization, synchronization)
        self._traj = rk.Trajectory(n)
        self.t0: float | None = None
        self._rest = None  # the target, when the state already is there (no trajectory)

    def plan(self, t0, p, v, a, target, vmax, amax, jmax, synchronized=True) -> float:
        """Plan from (p, v, a) at t0; not ``synchronized``: every DoF as fast as it can."""
        inp = self._inp
        inp.synchronization = self.synchronization if synchronized else self._rk.Synchronization.No
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
        except (self._rk.RuckigError, ValueError) as exc:  # ValueError: a code unknown to Python
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


class _Leashed:
    """The lead bound and the restarts of both trajectories (see the module)."""

    def _leash(self, max_lead) -> None:
        self.max_lead = float(checked_limits(max_lead, 1, 'max_lead')[0])
        self.lead = self.max_lead * self.vmax
        self.restarts = 0  # restarts from the measured state (follow)
        self.restarted_at = -np.inf  # time of the last restart

    def following(self, t: float, measured) -> bool:
        """
        Whether the servo follows: no restart in the last ``max_lead`` s, half the bound at most.

        ``measured``: the joint positions, or the frame's pose.
        """
        return t - self.restarted_at > self.max_lead and self._lead(t, measured) <= 0.5

    def _restart(self, t, position, velocity, acceleration, **how) -> None:
        """Plan again to the target from a state on the leash."""
        self.start(t, position, velocity, acceleration, self._target, **how)
        self.restarts += 1
        self.restarted_at = t


class JointTrajectory(_Leashed):
    def __init__(self, n: int, max_velocity, max_acceleration, max_jerk, max_lead=MAX_LEAD):
        self.vmax = checked_limits(max_velocity, n, 'max_velocity')
        self.amax = checked_limits(max_acceleration, n, 'max_acceleration')
        self.jmax = checked_limits(max_jerk, n, 'max_jerk')
        self._leash(max_lead)
        self._p = _Profile(n)
        self._target = np.zeros(n)
        self.active = False

    def start(self, t, position, velocity, acceleration, target, synchronized=True) -> float:
        """
        Plan to ``target``; all joints arrive together (``synchronized``) or each when it can.

        Returns the duration.
        """
        d = self._p.plan(
            t, position, velocity, acceleration, target, self.vmax, self.amax, self.jmax,
            synchronized,
        )
        self._target = np.array(target, dtype=float)
        self.active = True
        return d

    def follow(self, t: float, position):
        """
        (q, qd, qdd) at time t, within the lead bound of the measured ``position``.

        The joints further ahead restart on the leash, at rest (see the module).
        """
        q, qd, qdd = self.sample(t)
        position = np.asarray(position, dtype=float)
        q0 = leashed(q, position, self.lead)
        if q0 is None:
            return q, qd, qdd
        ahead = np.abs(q - position) > self.lead  # the others go on as they were
        q0, qd, qdd = np.where(ahead, q0, q), np.where(ahead, 0.0, qd), np.where(ahead, 0.0, qdd)
        # unsynchronised: a stuck joint must not hold the others back (synchronised, they would
        # slow down to arrive with it, and never arrive)
        self._restart(t, q0, qd, qdd, synchronized=False)
        return self.sample(t)

    def _lead(self, t, position) -> float:
        """Return the reference's lead on ``position`` at t, in bounds (1: on the leash)."""
        return float((np.abs(self.sample(t)[0] - position) / self.lead).max())

    def sample(self, t: float):
        """(q, qd, qdd) at time t (the target, at rest, after the end)."""
        return self._p.sample(t)

    def finished(self, t: float) -> bool:
        return self._p.done(t)


class CartesianTrajectory(_Leashed):
    def __init__(self, max_velocity, max_acceleration, max_jerk, max_lead=MAX_LEAD):
        """
        Limits as [linear, angular] pairs (m/s, rad/s; m/s^2, rad/s^2; m/s^3, rad/s^3).

        ``max_lead``: the lead bound in seconds at the velocity limits (see the module).
        """
        self.vmax = checked_limits(max_velocity, 2, 'max_velocity [linear, angular]')
        self.amax = checked_limits(max_acceleration, 2, 'max_acceleration [linear, angular]')
        self.jmax = checked_limits(max_jerk, 2, 'max_jerk [linear, angular]')
        self._leash(max_lead)
        self._target = np.eye(4)
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
        # norm limits. A start velocity across it (a measured one) gets its share too, or braking
        # it on an axis with a thousandth of the limits takes longer than Ruckig plans (-101)
        share = np.abs(d) / dist if dist > 1e-9 else np.full(3, 1.0 / np.sqrt(3.0))
        speed = float(np.linalg.norm(twist[:3]))
        if speed > 1e-6:
            share = np.maximum(share, np.abs(twist[:3]) / speed)
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
        self._target = target.copy()
        self.active = True
        return max(lin, ang)

    def follow(self, t: float, pose):
        """
        (pose, twist, acceleration) at time t, within the lead bound of the measured ``pose``.

        The position or orientation further ahead restarts on the leash, at rest (see the module).
        """
        ref, v, a = self.sample(t)
        pose = np.asarray(pose, dtype=float)
        p0 = leashed(ref[:3, 3], pose[:3, 3], self.lead[0])
        r0 = leashed(_turn(pose, ref), np.zeros(3), self.lead[1])
        if p0 is None and r0 is None:
            return ref, v, a
        start = ref.copy()
        for part, rows, fix in ((p0, slice(0, 3), 0), (r0, slice(3, 6), 1)):
            if part is not None:
                v[rows], a[rows] = 0.0, 0.0
                if fix:
                    start[:3, :3] = pose[:3, :3] @ pin.exp3(part)
                else:
                    start[:3, 3] = part
        self._restart(t, start, v, a)
        return self.sample(t)

    def _lead(self, t, pose) -> float:
        """Return the reference's lead on ``pose`` at t, in bounds (1: on the leash)."""
        ref = self.sample(t)[0]
        lin = np.linalg.norm(ref[:3, 3] - np.asarray(pose)[:3, 3]) / self.lead[0]
        return float(max(lin, np.linalg.norm(_turn(pose, ref)) / self.lead[1]))

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


def _turn(pose, ref) -> np.ndarray:
    """Rotation vector from ``pose``'s orientation to ``ref``'s, in ``pose``'s frame."""
    return pin.log3(np.asarray(pose)[:3, :3].T @ ref[:3, :3])
