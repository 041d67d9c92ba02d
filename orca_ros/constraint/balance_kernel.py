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
The balance constraint's rows, compiled: :mod:`.balance_constraint`'s maths in one kernel call.

The compiled cycle gives :class:`~.balance_constraint.BalanceConstraint` this kernel
(``use_kernel``): the constraint still gathers its inputs in Python (the contacts' support points,
the CoM's terms), and :func:`balance_rows` does the rest the reference does with numpy: the
support polygon (the monotone chain of :func:`~.balance_constraint.convex_hull_2d`, on the points
rounded to 12 decimals, duplicates dropped), its edges' outward normals, each edge's room and the
CoM's speed towards it, the bound (:class:`~.viable_bound.ViableBound`'s ``upper`` with neither
the one-step nor the viability term, the margin's time constant one horizon, braking at A once the
margin is spent; :func:`_bound`), the pendulum's cap and the rows. Formula for formula: the
kernel equals the reference to round-off (test_balance.py).
"""

from __future__ import annotations

import math

import numpy as np

from .viable_bound import FAR as _FAR  # rooms are clipped to this before the arithmetic
from ..utils.jit import njit


@njit
def _bound(room, v, acc, dt, h):
    """Return the largest admissible acceleration towards an edge (the balance's ViableBound)."""
    if room >= _FAR:
        return np.inf
    d = (room - h * v) * (2.0 / (h * h))  # the approach over the horizon
    if v > 0.0:  # the braking margin A r - v^2 / 2 shrinks at most with the time constant h
        d = min(d, (acc * room - 0.5 * (v * v)) / (v * h) - acc)
    return max(d, -acc)


@njit
def _before(a, b) -> bool:
    """Tell whether 2-D point a sorts before b (x, then y), as Python sorts tuples."""
    return a[0] < b[0] or (a[0] == b[0] and a[1] < b[1])


@njit
def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


@njit
def convex_hull(points, pts, hull) -> int:
    """
    Write the convex hull of the 2-D ``points`` (n x 2) into ``hull``, counter-clockwise.

    Return its vertex count (the points themselves, sorted and without duplicates, when fewer
    than 3). ``pts``: a buffer of n x 2 (the rounded, sorted points); ``hull``: of 2 n x 2.
    """
    n = 0
    for i in range(points.shape[0]):  # rounded, inserted in order, duplicates dropped
        x, y = np.round(points[i, 0], 12), np.round(points[i, 1], 12)
        at = n
        while at > 0 and (pts[at - 1, 0] > x or (pts[at - 1, 0] == x and pts[at - 1, 1] > y)):
            at -= 1
        if at > 0 and pts[at - 1, 0] == x and pts[at - 1, 1] == y:
            continue
        for j in range(n, at, -1):
            pts[j, 0], pts[j, 1] = pts[j - 1, 0], pts[j - 1, 1]
        pts[at, 0], pts[at, 1] = x, y
        n += 1
    if n < 3:
        for i in range(n):
            hull[i, 0], hull[i, 1] = pts[i, 0], pts[i, 1]
        return n
    k = 0
    for i in range(n):  # the lower chain
        while k >= 2 and _cross(hull[k - 2], hull[k - 1], pts[i]) <= 0.0:
            k -= 1
        hull[k, 0], hull[k, 1] = pts[i, 0], pts[i, 1]
        k += 1
    lower = k
    for i in range(n - 1, -1, -1):  # the upper chain
        while k >= lower + 2 and _cross(hull[k - 2], hull[k - 1], pts[i]) <= 0.0:
            k -= 1
        hull[k, 0], hull[k, 1] = pts[i, 0], pts[i, 1]
        k += 1
    # lower[:-1] + upper[:-1]: the upper chain's first point is the lower's last
    for i in range(lower - 1, k - 2):
        hull[i, 0], hull[i, 1] = hull[i + 1, 0], hull[i + 1, 1]
    return k - 2


@njit
def balance_rows(support, p, J, v, bias, g, margin, max_acc, horizon, dt, acc0, C, lb, ub,
                 pts, hull, normals) -> int:
    """
    Write the balance rows into C, lb, ub (all of them: unused rows relaxed); return the edges.

    ``support``: the support points (n x 3, world); ``p``, ``J``, ``v``, ``bias``: the CoM's
    position, Jacobian (3 x nv), velocity and bias; ``g``: gravity's downward magnitude;
    ``acc0``: the rows' first column (the accelerations'); ``pts``, ``hull``, ``normals``:
    buffers (n x 2, 2 n x 2, n x 2). Fewer than 3 hull vertices: every row relaxed.
    """
    for i in range(C.shape[0]):
        for c in range(C.shape[1]):
            C[i, c] = 0.0
        lb[i] = -np.inf
        ub[i] = np.inf
    k = convex_hull(support[:, :2], pts, hull)
    if k < 3:
        return k
    height = 0.0
    for i in range(support.shape[0]):
        height += support[i, 2]
    omega2 = g / max(p[2] - height / support.shape[0], 1e-3)
    acc = max(min(max_acc, omega2 * margin), 1e-6)
    h = max(horizon, dt)
    for i in range(k):
        j = i + 1 if i + 1 < k else 0
        ex, ey = hull[j, 0] - hull[i, 0], hull[j, 1] - hull[i, 1]
        norm = math.sqrt(ey * ey + ex * ex)
        nx, ny = ey / norm, -ex / norm  # outward for a counter-clockwise polygon
        normals[i, 0], normals[i, 1] = nx, ny
        room = (nx * hull[i, 0] + ny * hull[i, 1]) - (nx * p[0] + ny * p[1])
        bound = _bound(min(room - margin, _FAR), nx * v[0] + ny * v[1], acc, dt, h)
        bound = max(bound, -omega2 * room)
        for c in range(J.shape[1]):
            C[i, acc0 + c] = nx * J[0, c] + ny * J[1, c]
        ub[i] = bound - (nx * bias[0] + ny * bias[1])
    return k
