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
Viable acceleration bound towards a limit, in discrete time, for many limits in one pass.

For a coordinate with ``room`` = limit - position (>= 0 inside) and velocity ``v`` towards the
limit, under a constant acceleration a over one step dt (p' = p + dt v + dt^2/2 a, v' = v + dt a)
and A the deceleration that can always be produced, the largest admissible a is the least of:

* the next position within the limit: a <= 2 (room - dt v) / dt^2 (exact, no excursion);
* the next state able to stop before the limit at A (after Del Prete, RA-L 2018): v'^2 <= 2 A
  (room - dt v - dt^2/2 a) when v' > 0, the larger root of a quadratic in a, or -v/dt (the step
  ends at rest or moving away) when no root exists or it is smaller;
* a smoother approach over a horizon h, p + h v + h^2/2 a <= limit, as far as it asks for no more
  than A;
* the braking margin s = room - v^2 / (2 A) (what is left after braking at A) shrinks no faster
  than with the time constant h / 2: ds/dt = -v (1 + a / A) >= -2 s / h, i.e. for v > 0
  a <= 2 (A room - v^2 / 2) / (h v) - A. Without it, the viability bound alone is a wall in
  acceleration: its gain on the velocity is 1 / dt, so a joint driven hard towards its limit
  meets it in one cycle, its torque stepping; with it the braking sets in over ~h / 2 (h shapes
  the transients, and with them where a redundant arm's null-space drift is at a given time:
  test_other_arms.py's xArm7 checks such a phase). In the
  continuous limit it is the tighter of the two (2 / h <= 1 / dt), and it equals -A on the
  viability boundary, so it takes nothing from the states that can still stop. Where s <= 0 it
  does not apply (it would ask for more than A: a joint resting on its limit and creeping
  towards it at 1e-6 rad/s would be pushed off at A, and chatter there).

In a viable state a = -A stays admissible, so the bound is never empty and braking never needs
more than A; a state that is not viable (a start close to the limit, a push) brakes at A and only
the one-step bound may ask for more. Used by the joint position limits (both sides of every joint
stacked), the collision avoidance (without the one-step term) and the balance constraint (the
centre of mass towards each edge of the support polygon: without the one-step and viability
terms, the margin shrinking with h).

:class:`ViableBound` holds its buffers (no allocation per cycle); an infinite room gives an
infinite bound.
"""

from __future__ import annotations

import numpy as np

# rooms are clipped to this before the arithmetic (no inf - inf); their bound is set to +inf after
FAR = 1e6
# the braking margin's time constant, a share of the horizon
MARGIN_SHARE = 0.5


class ViableBound:
    def __init__(self, size: int):
        self.size = int(size)
        n = self.size
        self._room, self._a, self._b, self._c = (np.zeros(n) for _ in range(4))
        self._d, self._e, self._f = np.zeros(n), np.zeros(n), np.zeros(n)
        self._towards = np.zeros(n, dtype=bool)
        self._far = np.zeros(n, dtype=bool)
        self._no_root = np.zeros(n, dtype=bool)
        self._acc = np.ones(n)
        self._acc_dt = None  # dt of the cached products of A below
        self._acc_dt2, self._acc_m2, self._acc_neg = np.zeros(n), np.zeros(n), np.zeros(n)

    def set_acceleration(self, acc) -> None:
        """Set A, the deceleration that can always be produced: scalar or one per limit, > 0."""
        self._acc[:] = acc
        self._acc_dt = None

    def upper(
        self,
        room,
        v,
        dt: float,
        horizon: float,
        out,
        one_step: bool = True,
        viable: bool = True,
        margin_share: float = MARGIN_SHARE,
        brake_when_spent: bool = False,
        margin: bool = True,
    ) -> np.ndarray:
        """
        Write into ``out`` the largest admissible acceleration towards each limit.

        ``room``, ``v``: arrays of ``size``; ``horizon`` >= dt. ``one_step=False`` leaves out the
        exact next-position bound: the result then never asks for more than braking at A (for
        limits that move and may leave the state outside them). ``viable=False`` leaves out the
        next state's viability (a stop within one step: a bound whose braking A is a model, not
        the actuators' limit); ``margin_share``: the braking margin's time constant in horizons;
        ``brake_when_spent``: brake at A where the margin is spent too (s <= 0, moving towards the
        limit), not only where it shrinks; ``margin=False`` leaves the braking margin's term out
        (what the bound is without it: the collision rows limit how fast that term alone tightens).
        """
        R, a, d, e = self._room, self._a, self._d, self._e
        if self._acc_dt != dt:
            self._acc_dt = dt
            np.multiply(self._acc, dt * dt, out=self._acc_dt2)
            np.multiply(self._acc, -2.0, out=self._acc_m2)
            np.negative(self._acc, out=self._acc_neg)
        np.greater_equal(room, FAR, out=self._far)
        np.minimum(room, FAR, out=R)
        dt2 = dt * dt
        np.multiply(v, dt, out=a)
        np.subtract(R, a, out=a)  # a: room - dt v
        if viable:
            self._viable(v, dt)
        else:
            d.fill(np.inf)
        # smooth approach over the horizon, capped at braking with A
        h = horizon
        np.multiply(v, -h, out=e)
        np.add(e, R, out=e)
        np.multiply(e, 2.0 / (h * h), out=e)
        np.minimum(d, e, out=d)
        # the braking margin shrinks at most with the time constant margin_share h (towards the
        # limit only)
        if not margin:
            np.maximum(d, self._acc_neg, out=d)
            return self._finish(a, d, dt2, one_step, out)
        f = self._f
        np.multiply(self._acc, R, out=f)
        f -= 0.5 * np.square(v, out=e)  # f: A s, the margin times A
        if brake_when_spent:
            np.greater(v, 0.0, out=self._towards)
        else:
            np.greater(f, 0.0, out=self._towards)
            self._towards &= v > 0.0
        np.multiply(v, margin_share * h, out=e)
        np.divide(f, e, out=f, where=self._towards)
        f -= self._acc
        np.minimum(d, f, out=d, where=self._towards)
        np.maximum(d, self._acc_neg, out=d)
        return self._finish(a, d, dt2, one_step, out)

    def _finish(self, a, d, dt2: float, one_step: bool, out) -> np.ndarray:
        if one_step:  # the next position within the limit, exactly
            np.multiply(a, 2.0 / dt2, out=a)
            np.minimum(a, d, out=out)
        else:
            out[:] = d
        out[self._far] = np.inf
        return out

    def _viable(self, v, dt: float) -> None:
        """Write into ``_d`` the largest a whose next state can stop before the limit at A."""
        a, b, c, d, e = self._a, self._b, self._c, self._d, self._e
        dt2 = dt * dt
        # b = 2 v dt + A dt^2,  c = v^2 - 2 A (room - dt v),  disc = b^2 - 4 dt^2 c
        np.multiply(v, 2.0 * dt, out=b)
        np.add(b, self._acc_dt2, out=b)
        np.multiply(a, self._acc_m2, out=c)
        np.add(c, np.square(v, out=d), out=c)
        np.square(b, out=d)
        np.subtract(d, np.multiply(c, 4.0 * dt2, out=c), out=d)  # d: disc
        np.less(d, 0.0, out=self._no_root)
        np.maximum(d, 0.0, out=d)
        np.sqrt(d, out=d)
        np.subtract(d, b, out=d)
        np.multiply(d, 0.5 / dt2, out=d)  # d: larger root
        np.multiply(v, -1.0 / dt, out=e)  # e: stop within the step
        np.maximum(d, e, out=d)
        np.copyto(d, e, where=self._no_root)  # d: viable
