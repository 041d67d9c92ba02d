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
The leash of a target trajectory: its reference leads the measured state by a bound at most.

The bound (per part, the trajectories' ``follow``): the distance the reference covers in
``max_lead`` seconds [0.2 s] at its velocity limit (5 cm and 0.2 rad with the Cartesian defaults,
0.2 s of half the URDF velocity for joints). A servo that follows tracks
within millimetres (the shipped arm: a few mm at most at 0.25 m/s, kp 400 with feed-forward), far
inside it; a servo that cannot (a target out of reach, a constraint in the way) would leave the
reference running on towards the target, and the next target would start from there, metres away
and at full speed. Instead the reference brakes on its leash: a part (position, orientation; or a
joint) past a quarter of the bound whose lead would pass the bound before it could stop (its lead
growing at u . (v_ref - v_measured), u the lead's direction, while the reference brakes within its
acceleration and jerk limits) is brought to rest as fast as those limits allow, from the state it
is in: a new Ruckig profile from the sampled position, velocity and acceleration, so the velocity
and acceleration fed forward never step (a step there is a torque step). A lead that passes the
bound all the same (from the velocity limit, braking takes longer than the bound's 0.2 s; the
robot may move away) is moved back onto the bound and brakes on with the velocity and acceleration
it had: the reference slides along the bound until it stops. At rest it waits there (a steady
pull: the servo's gain times the lead, damping the robot's own velocity) and goes on to the same
target once the robot has come within a quarter of the bound (where braking cannot start). Braking
always ends at rest, so a reference never cruises on along its bound. Two choices keep a stretched
arm at a target out of reach from being whipped by the velocity fed forward, which it can only
meet through a near-singular joint (the lwr's joint 3 driven past 6.7 rad/s, 2.2 rad/s its limit):
a brake is harder than the cruise (5x the acceleration limit, 20x the jerk limit: a stop in tens
of milliseconds, each millisecond's change of the acceleration fed forward still small), and a
reference at rest waits until the robot has nearly caught up (going on within half the bound, the
creeping arm set it off and braked it again and again).

``following`` tells whether the servo follows (no brake in the last ``max_lead`` seconds, the lead
at most half the bound); when it does not, a new target is best started from the measured state,
not from the reference on the leash ahead of it. Without a measured velocity, it is estimated from
the measured positions (differences, low-passed).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

# the reference leads the measured state by at most what it covers in this time at its velocity
# limit (see the module)
MAX_LEAD = 0.2
# a profile this slow (per s, per s^2) is at rest
AT_REST = 1e-9
# the measured velocity, when not given, from the positions' differences low-passed over this [s]
VELOCITY_FILTER = 0.02
# a brake's acceleration and jerk limits, in multiples of the trajectory's (see the module)
BRAKE_ACCELERATION, BRAKE_JERK = 5.0, 20.0


def stop_distance(v, a, amax, jmax):
    """
    Return an upper bound of the distance covered braking from speed ``v`` to rest (elementwise).

    ``a``: the acceleration along the motion (> 0 speeding up); braking within ``amax`` and
    ``jmax``. First the acceleration is ramped to 0 (the speed still grows by a^2 / (2 jmax) while
    it does), then the time-optimal stop from that speed with no acceleration: a triangular
    profile below amax^2 / jmax, a trapezoidal one above.
    """
    v = np.maximum(np.asarray(v, dtype=float), 0.0)
    up = np.maximum(np.asarray(a, dtype=float), 0.0)
    peak = v + up * up / (2.0 * jmax)
    ramp = peak * up / jmax
    trapezoid = peak * peak / (2.0 * amax) + peak * amax / (2.0 * jmax)
    triangle = peak * np.sqrt(peak / jmax)
    return ramp + np.where(peak >= amax * amax / jmax, trapezoid, triangle)


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


def pose_step(x, x_prev) -> np.ndarray:
    """Displacement [linear; angular] (world axes) from pose ``x_prev`` to ``x`` (4x4 each)."""
    return np.concatenate(
        (x[:3, 3] - x_prev[:3, 3], x_prev[:3, :3] @ pin.log3(x_prev[:3, :3].T @ x[:3, :3]))
    )


class Leash:
    """
    One trajectory's lead bound: when a part brakes, when it goes on (see the module).

    ``bound`` per part (joints; or [position, orientation]), reached in ``max_lead`` s at the
    velocity limits; ``amax``, ``jmax``: the parts' acceleration and jerk limits, which a brake
    exceeds by BRAKE_ACCELERATION and BRAKE_JERK (``self.amax``, ``self.jmax``). ``brakes``
    counts the parts that started braking (or were moved back onto the bound), ``braked_at`` is
    the last time.
    """

    def __init__(self, bound, max_lead: float, amax, jmax):
        self.bound = np.asarray(bound, dtype=float)
        self.max_lead = float(max_lead)
        self.amax = BRAKE_ACCELERATION * np.asarray(amax, dtype=float)
        self.jmax = BRAKE_JERK * np.asarray(jmax, dtype=float)
        self.brakes = 0
        self.braked_at = -np.inf
        self._t, self._x, self._v = None, None, None  # the measured velocity's estimate
        self._t_follow = None  # the last decision's time

    def measured_velocity(self, t: float, x, diff, given=None) -> np.ndarray | None:
        """
        Return ``given``, else the measured ``x``'s rate (None before two samples).

        Differences (``diff(x, x_prev)``: the displacement) low-passed over VELOCITY_FILTER,
        starting from rest.
        """
        if given is not None:
            return np.asarray(given, dtype=float)
        if self._t is not None and t > self._t:
            raw = diff(x, self._x) / (t - self._t)
            last = np.zeros_like(raw) if self._v is None else self._v
            self._v = last + min(1.0, (t - self._t) / VELOCITY_FILTER) * (raw - last)
        if self._t is None or t > self._t:
            self._t, self._x = t, np.array(x, dtype=float)
        return self._v

    def decide(self, t: float, lead, rate, acc, braking, at_rest):
        """
        Per part, at time t: (go on, past the bound, brake) masks.

        ``lead``: the lead, ``rate`` its growth, ``acc`` the reference's acceleration along it
        (the next decision is taken as far ahead as this one is after the last);
        ``braking``: the parts braking or held,
        ``at_rest``: those whose reference is at rest. A lead within a quarter of the bound never
        brakes: a servo that follows is far inside it, and a lead's rate from jittery
        measurements is no reason to stop.
        """
        dt = 0.0 if self._t_follow is None else max(t - self._t_follow, 0.0)
        self._t_follow = t
        bound = self.bound
        ahead = lead > bound
        resume = braking & at_rest & (lead <= 0.25 * bound) & ~ahead  # caught up
        coming = lead + np.maximum(rate, 0.0) * dt + stop_distance(rate, acc, self.amax, self.jmax)
        brake = ~braking & ~ahead & (rate > 0.0) & (lead > 0.25 * bound) & (coming > bound)
        started = (ahead & ~braking) | brake
        if started.any():
            self.brakes += 1
            self.braked_at = t
        return resume, ahead, brake

    def following(self, t: float, lead_ratio: float) -> bool:
        """Tell whether the servo follows: no brake in the last ``max_lead`` s, half the bound."""
        return t - self.braked_at > self.max_lead and lead_ratio <= 0.5
