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
Balance: the centre of mass kept over the support polygon, with a margin.

The support polygon is the convex hull, in the horizontal plane, of the points of every active
contact (a point contact's point, a sole's corners), recomputed every cycle; shrunk by ``margin``
it gives one half-plane per edge, n_i . c_xy <= d_i. Each edge bounds the CoM's acceleration
towards it, c_ddot = J_com nu_dot + J_dot_com nu: the CoM approaches the shrunk edge over
``horizon`` (h), and its braking margin r - v^2 / (2 A) (the room r left after braking at A)
shrinks no faster than with the time constant h (:class:`~.viable_bound.ViableBound` without its
one-step and viability terms; the joint limits' margin shrinks with h / 2): the CoM stops before
the edge. A CoM
target outside the polygon then saturates at its boundary instead of throwing the robot over it.

The braking asked for is what the feet can give. The linear inverted pendulum (omega^2 = g / h,
h the CoM's height over the support points) decelerates the CoM at omega^2 times its distance to
an edge at most, the centre of pressure on that edge: the CoM stops before the shrunk edge braking
at min(``max_acceleration``, omega^2 margin), what it still gets there, and is never asked for more
than omega^2 times its distance to the edge where it is. A larger demand is met only by tilting
the body (angular momentum): with the defaults, the shipped quadruped meets a hard side push
mostly by tilting. Nor does the bound demand a stop within one cycle (no one-step term): the
polygon moves with the contacts (a foot lifted, a sole switched off) and may leave the CoM outside.

A push may still leave no solution (the capture point out of the polygon: a fall without a step):
these rows are then among what the elastic fallback of the failed cycle relaxes (``elastic``, see
optim/elastic_contacts.py). With fewer than three support points (no polygon) the rows are
relaxed.

Rows: one per possible hull edge (the number of support points of all contacts), sized when the
contacts change; unused rows are relaxed.
"""

from __future__ import annotations

import numpy as np

from .generic_constraint import GenericConstraint
from .viable_bound import ViableBound


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Return the vertices of the convex hull of 2-D points, counter-clockwise (monotone chain)."""
    pts = sorted(set(map(tuple, np.round(points, 12))))
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0.0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0.0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def polygon_room(points: np.ndarray, p) -> float:
    """Return the distance of the 2-D point p inside the convex hull of points (< 0 outside)."""
    hull = convex_hull_2d(points)
    e = np.roll(hull, -1, axis=0) - hull
    n = np.column_stack((e[:, 1], -e[:, 0]))
    n /= np.linalg.norm(n, axis=1)[:, None]
    return float(np.min(np.einsum('ij,ij->i', n, hull) - n @ np.asarray(p)))


def _carries_load(contact) -> bool:
    """Tell whether a contact may carry load now (one ramping in from 0 may not yet)."""
    bound = getattr(contact, 'normal_force_bound', None)  # bilateral contacts have none
    return bound is None or bound() > 0.0


class BalanceConstraint(GenericConstraint):
    elastic = True  # a failed cycle is solved again with these rows soft (optim/elastic_contacts)

    def __init__(
        self,
        name: str,
        margin: float = 0.03,
        max_acceleration: float = 2.0,
        horizon: float = 0.2,
    ):
        super().__init__(name)
        self.set_margin(margin)
        self.set_max_acceleration(max_acceleration)
        self.set_horizon(horizon)
        self.polygon = np.zeros((0, 2))  # the last support polygon (not shrunk), CCW
        self._kernel = None  # balance_kernel.balance_rows in the compiled cycle (use_kernel)

    def use_kernel(self, on: bool) -> None:
        """Compute the rows by the compiled kernel (:mod:`.balance_kernel`), or in numpy."""
        if on:
            from .balance_kernel import balance_rows  # noqa: PLC0415 (numba: compiled cycle only)

            self._kernel = balance_rows
        else:
            self._kernel = None

    def set_margin(self, margin: float) -> None:
        """Distance kept between the CoM and the polygon's edges [m], >= 0."""
        if not (np.isfinite(margin) and margin >= 0.0):
            raise ValueError(f"constraint '{self.name}': margin must be finite and >= 0")
        self.margin = float(margin)

    def set_max_acceleration(self, value: float) -> None:
        """Most deceleration the bound asks of the CoM [m/s^2], > 0 (omega^2 margin if less)."""
        if not (np.isfinite(value) and value > 0.0):
            raise ValueError(f"constraint '{self.name}': max acceleration must be finite and > 0")
        self.max_acceleration = float(value)

    def set_horizon(self, horizon: float) -> None:
        """Time over which the CoM approaches an edge [s], > 0."""
        if not (np.isfinite(horizon) and horizon > 0.0):
            raise ValueError(f"constraint '{self.name}': horizon must be finite and > 0")
        self.horizon = float(horizon)

    def rows(self) -> int:
        return sum(c.support_point_count for c in self.layout.contacts)

    def resize(self, layout) -> None:
        super().resize(layout)
        m = self.rows()
        self._room, self._vel, self._out = np.zeros(m), np.zeros(m), np.zeros(m)
        self._shrunk, self._bound = np.zeros(m), ViableBound(m)
        self._normals = np.zeros((m, 2))
        self._pts, self._hull = np.zeros((m, 2)), np.zeros((2 * m, 2))  # (the kernel's)

    def _support(self) -> np.ndarray:
        pts = [
            c.support_points()
            for c in self.layout.contacts
            if c.is_computing() and _carries_load(c)
        ]
        return np.concatenate(pts) if pts else np.zeros((0, 3))

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        m = self.C.shape[0]
        if self._kernel is not None and m:
            support = self._support()
            p, J, v, bias = self.robot.get_center_of_mass_terms()
            g = max(float(-self.robot.get_gravity()[2]), 0.0)
            k = self._kernel(support, p, J, v, bias, g, self.margin, self.max_acceleration,
                             self.horizon, dt, self.layout.acc.start, self.C, self.lb, self.ub,
                             self._pts, self._hull, self._normals)
            self.polygon = self._hull[:k].copy()
            return
        self.C.fill(0.0)
        self.lb.fill(-np.inf)
        self.ub.fill(np.inf)
        support = self._support() if m else np.zeros((0, 3))
        hull = convex_hull_2d(support[:, :2])
        self.polygon = hull
        k = hull.shape[0]
        if k < 3:
            return
        edges = np.roll(hull, -1, axis=0) - hull
        n = self._normals[:k]
        n[:, 0], n[:, 1] = edges[:, 1], -edges[:, 0]  # outward for a CCW polygon
        n /= np.linalg.norm(n, axis=1)[:, None]
        p, J, v, bias = self.robot.get_center_of_mass_terms()
        room, vel, out = self._room, self._vel, self._out
        room.fill(np.inf)
        vel.fill(0.0)
        # distance to each edge, and the CoM's speed towards it
        room[:k] = np.einsum('ij,ij->i', n, hull) - n @ p[:2]
        vel[:k] = n @ v[:2]
        # the linear inverted pendulum (omega^2 = g / the CoM's height) brakes the CoM at
        # omega^2 x its distance to the edge, the centre of pressure on the edge: the CoM stops
        # before the shrunk edge braking at no more than it gets there, omega^2 margin, and is
        # never asked for more than it gets where it is
        g = max(float(-self.robot.get_gravity()[2]), 0.0)
        omega2 = g / max(p[2] - support[:, 2].mean(), 1e-3)
        acc = max(min(self.max_acceleration, omega2 * self.margin), 1e-6)
        # approach the shrunk edge over the horizon h, and let the braking margin r - v^2 / (2 A)
        # shrink no faster than with the time constant h (moving towards it), braking at A at
        # most, and at A once the margin is spent (a push: without it, a hard side push made
        # cycles fail); no one-step or viability term (A is the pendulum's, and the polygon moves)
        np.subtract(room, self.margin, out=self._shrunk)
        self._bound.set_acceleration(acc)
        self._bound.upper(self._shrunk, vel, dt, max(self.horizon, dt), out, one_step=False,
                          viable=False, margin_share=1.0, brake_when_spent=True)
        np.maximum(out[:k], -omega2 * room[:k], out=out[:k])
        self.C[:k, self.layout.acc] = n @ J[:2]
        self.ub[:k] = out[:k] - n @ bias[:2]
