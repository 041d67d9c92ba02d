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

The reference never leads the measured state by more than a bound (:meth:`follow`): it brakes on
its leash (:mod:`orca_ros.servo.leash`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .leash import AT_REST, Leash, leashed, MAX_LEAD, pose_step
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
        self.synchronization = getattr(rk.Synchronization, synchronization)
        self._traj = rk.Trajectory(n)
        self.t0: float | None = None
        self._rest = None  # the target, when the state already is there (no trajectory)

    def plan(
        self, t0, p, v, a, target, vmax, amax, jmax, synchronized=True, braking=None
    ) -> float:
        """
        Plan from (p, v, a) at t0; not ``synchronized``: every DoF as fast as it can.

        ``braking`` (a mask, or True for all): those DoF are brought to rest as fast as the limits
        allow (Ruckig's velocity interface), their target position ignored.
        """
        inp, rk = self._inp, self._rk
        inp.synchronization = self.synchronization if synchronized else rk.Synchronization.No
        mask = np.broadcast_to(np.asarray(False if braking is None else braking), (self.n,))
        inp.control_interface = (
            rk.ControlInterface.Velocity if mask.all() else rk.ControlInterface.Position
        )
        inp.per_dof_control_interface = (
            [rk.ControlInterface.Velocity if b else rk.ControlInterface.Position for b in mask]
            if mask.any() and not mask.all() else None
        )
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
    """What both trajectories tell of their leash (``self.leash``, ``self._lead``)."""

    leash: Leash

    @property
    def lead(self) -> np.ndarray:
        """Return the lead bound per part (see :mod:`orca_ros.servo.leash`)."""
        return self.leash.bound

    @property
    def brakes(self) -> int:
        """Return how many times a part braked on the leash (or was moved back onto it)."""
        return self.leash.brakes

    def following(self, t: float, measured) -> bool:
        """
        Whether the servo follows: no brake in the last ``max_lead`` s, half the bound at most.

        ``measured``: the joint positions, or the frame's pose.
        """
        return self.leash.following(t, self._lead(t, measured))


class JointTrajectory(_Leashed):
    def __init__(self, n: int, max_velocity, max_acceleration, max_jerk, max_lead=MAX_LEAD):
        self.vmax = checked_limits(max_velocity, n, 'max_velocity')
        self.amax = checked_limits(max_acceleration, n, 'max_acceleration')
        self.jmax = checked_limits(max_jerk, n, 'max_jerk')
        max_lead = float(checked_limits(max_lead, 1, 'max_lead')[0])
        self.leash = Leash(max_lead * self.vmax, max_lead, self.amax, self.jmax)
        self._p = _Profile(n)
        self._target = np.zeros(n)
        self._braking = np.zeros(n, dtype=bool)
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
        self._braking[:] = False
        self.active = True
        return d

    def follow(self, t: float, position, velocity=None):
        """
        (q, qd, qdd) at time t, within the lead bound of the measured ``position``.

        ``velocity``: the measured joint velocities (None: estimated from the positions). Joints
        that would pass the bound brake, alone (see the module).
        """
        q, qd, qdd = self.sample(t)
        position = np.asarray(position, dtype=float)
        vm = self.leash.measured_velocity(t, position, np.subtract, velocity)
        vm = np.zeros_like(q) if vm is None else vm
        d = q - position
        side = np.sign(d)
        at_rest = (np.abs(qd) <= AT_REST) & (np.abs(qdd) <= AT_REST)
        resume, ahead, brake = self.leash.decide(
            t, np.abs(d), side * (qd - vm), side * qdd, self._braking, at_rest
        )
        if not (resume.any() or ahead.any() or brake.any()):
            return q, qd, qdd
        # past the bound: moved back onto it, braking on from the velocity and acceleration it had
        p0 = np.where(ahead, position + np.clip(d, -self.lead, self.lead), q)
        held = (self._braking & ~resume) | ahead | brake
        # unsynchronised: a stuck joint must not hold the others back (synchronised, they would
        # slow down to arrive with it, and never arrive)
        self._p.plan(
            t, p0, qd, qdd, self._target, self.vmax, np.where(held, self.leash.amax, self.amax),
            np.where(held, self.leash.jmax, self.jmax), synchronized=False, braking=held,
        )
        self._braking = held
        return self.sample(t)

    def _lead(self, t, position) -> float:
        """Return the reference's lead on ``position`` at t, in bounds (1: on the leash)."""
        return float((np.abs(self.sample(t)[0] - position) / self.lead).max())

    def sample(self, t: float):
        """(q, qd, qdd) at time t (the target, at rest, after the end)."""
        return self._p.sample(t)

    def finished(self, t: float) -> bool:
        return self._p.done(t) and not self._braking.any()


def _share(direction) -> np.ndarray:
    """Per-axis shares of the norm limits for a straight line along ``direction``."""
    n = float(np.linalg.norm(direction))
    share = np.abs(direction) / n if n > 1e-9 else np.full(3, 1.0 / np.sqrt(3.0))
    return np.maximum(share, 1e-3)


class CartesianTrajectory(_Leashed):
    def __init__(self, max_velocity, max_acceleration, max_jerk, max_lead=MAX_LEAD):
        """
        Limits as [linear, angular] pairs (m/s, rad/s; m/s^2, rad/s^2; m/s^3, rad/s^3).

        ``max_lead``: the lead bound in seconds at the velocity limits (see the module).
        """
        self.vmax = checked_limits(max_velocity, 2, 'max_velocity [linear, angular]')
        self.amax = checked_limits(max_acceleration, 2, 'max_acceleration [linear, angular]')
        self.jmax = checked_limits(max_jerk, 2, 'max_jerk [linear, angular]')
        max_lead = float(checked_limits(max_lead, 1, 'max_lead')[0])
        self.leash = Leash(max_lead * self.vmax, max_lead, self.amax, self.jmax)
        self._target = np.eye(4)
        self._lin = _Profile(3, 'Phase')
        self._ang = _Profile(1)
        self._R0 = np.eye(3)
        self._axis = np.array([0.0, 0.0, 1.0])
        self._braking = np.zeros(2, dtype=bool)  # [position, orientation] held on the leash
        self.active = False
        self._out = np.eye(4)

    def start(self, t, pose, twist, acceleration, target) -> float:
        """
        From ``pose`` (4x4).

        ``twist`` and ``acceleration`` ([linear, angular], base frame) to ``target``.
        """
        pose, target = np.asarray(pose, dtype=float), np.asarray(target, dtype=float)
        twist, acceleration = np.asarray(twist, dtype=float), np.asarray(acceleration, dtype=float)
        self._target = target.copy()
        self._braking[:] = False
        lin = self._plan_linear(t, pose[:3, 3], twist[:3], acceleration[:3])
        ang = self._plan_angular(t, pose[:3, :3], twist[3:], acceleration[3:])
        self.active = True
        return max(lin, ang)

    def _plan_linear(self, t, p, v, a) -> float:
        """Plan the position's straight line from (p, v, a) to the target's."""
        target = self._target[:3, 3]
        # per-axis limits in proportion to the direction: from rest, a straight line within the
        # norm limits. A start velocity across it (a measured one) gets its share too, or braking
        # it on an axis with a thousandth of the limits takes longer than Ruckig plans (-101)
        share = _share(target - p)
        speed = float(np.linalg.norm(v))
        if speed > 1e-6:
            share = np.maximum(share, np.abs(v) / speed)
        return self._lin.plan(
            t, p, v, a, target, self.vmax[0] * share, self.amax[0] * share, self.jmax[0] * share
        )

    def _plan_angular(self, t, R, w, a) -> float:
        """Plan the rotation about one fixed axis from R (angular velocity w, acceleration a)."""
        self._R0 = np.array(R, dtype=float)
        rotvec = pin.log3(self._R0.T @ self._target[:3, :3])  # in the start frame
        angle = float(np.linalg.norm(rotvec))
        self._axis = rotvec / angle if angle > 1e-12 else np.array([0.0, 0.0, 1.0])
        axis_base = self._R0 @ self._axis
        return self._ang.plan(
            t, [0.0], [float(axis_base @ w)], [float(axis_base @ a)], [angle],
            self.vmax[1:], self.amax[1:], self.jmax[1:],
        )

    def follow(self, t: float, pose, twist=None):
        """
        (pose, twist, acceleration) at time t, within the lead bound of the measured ``pose``.

        ``twist``: the measured one ([linear, angular], base frame; None: estimated from the
        poses). The position or orientation that would pass the bound brakes (see the module).
        """
        ref, v, a = self.sample(t)
        pose = np.asarray(pose, dtype=float)
        vm = self.leash.measured_velocity(t, pose, pose_step, twist)
        vm = np.zeros(6) if vm is None else vm
        d = ref[:3, 3] - pose[:3, 3]
        turn = pose[:3, :3] @ _turn(pose, ref)  # world axes
        lead = np.array([np.linalg.norm(d), np.linalg.norm(turn)])
        u = [x / n if n > 0.0 else np.zeros(3) for x, n in zip((d, turn), lead)]
        rate = np.array([u[0] @ (v[:3] - vm[:3]), u[1] @ (v[3:] - vm[3:])])
        acc = np.array([u[0] @ a[:3], u[1] @ a[3:]])
        at_rest = np.array([
            max(np.abs(v[:3]).max(), np.abs(a[:3]).max()) <= AT_REST,
            max(np.abs(v[3:]).max(), np.abs(a[3:]).max()) <= AT_REST,
        ])
        resume, ahead, brake = self.leash.decide(t, lead, rate, acc, self._braking, at_rest)
        if not (resume.any() or ahead.any() or brake.any()):
            return ref, v, a
        # past the bound: moved back onto it, braking on from the twist and acceleration it had
        if ahead[0]:
            p0 = leashed(ref[:3, 3], pose[:3, 3], self.lead[0])
            self._brake_linear(t, p0, v[:3], a[:3])
        elif brake[0]:
            self._brake_linear(t, ref[:3, 3], v[:3], a[:3])
        elif resume[0]:
            self._plan_linear(t, ref[:3, 3], np.zeros(3), np.zeros(3))
        if ahead[1]:
            r0 = leashed(_turn(pose, ref), np.zeros(3), self.lead[1])
            th, thd, thdd = self._ang.sample(t)
            axis = self._R0 @ self._axis  # the same axis (world), from the pose on the bound
            self._R0 = pose[:3, :3] @ pin.exp3(r0)
            self._axis = self._R0.T @ axis
            self._ang.plan(t, [0.0], thd, thdd, [0.0], self.vmax[1:], self.leash.amax[1:],
                           self.leash.jmax[1:], braking=True)
        elif brake[1]:
            th, thd, thdd = self._ang.sample(t)
            self._ang.plan(t, th, thd, thdd, th, self.vmax[1:], self.leash.amax[1:],
                           self.leash.jmax[1:], braking=True)
        elif resume[1]:
            self._plan_angular(t, ref[:3, :3], np.zeros(3), np.zeros(3))
        self._braking = (self._braking & ~resume) | ahead | brake
        return self.sample(t)

    def _brake_linear(self, t, p, v, a) -> None:
        """Bring the position to rest along its velocity, as fast as the brake's limits allow."""
        share = _share(v)
        self._lin.plan(t, p, v, a, p, self.vmax[0] * share, self.leash.amax[0] * share,
                       self.leash.jmax[0] * share, braking=True)

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
        return self._lin.done(t) and self._ang.done(t) and not self._braking.any()


def _turn(pose, ref) -> np.ndarray:
    """Rotation vector from ``pose``'s orientation to ``ref``'s, in ``pose``'s frame."""
    return pin.log3(np.asarray(pose)[:3, :3].T @ ref[:3, :3])
