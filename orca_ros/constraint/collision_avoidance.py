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
Collision avoidance in the torque QP: self collisions and obstacles, discrete-time and viable.

For each pair of convex bodies closer than ``influence_distance``
(:class:`~orca_ros.robot.collision_geometry.CollisionGeometry`: the URDF's collision geometry,
self pairs minus adjacent bodies and an SRDF's disabled pairs, plus obstacles), with d the
distance, p1, p2 the witness points and n the unit normal from the first body to the second:

    d_dot = n . (v_p2 - v_p1),   d_ddot ~= n . (J_p2 - J_p1) nu_dot + n . (a_p2 - a_p1)

(J_p the Jacobian of a point fixed on its body at the witness point, a_p its acceleration at
nu_dot = 0; the rate of n is neglected, as in the velocity damper of Faverjon and Tournassoud and
its acceleration-level forms). The distance is a coordinate with a lower limit
``safety_distance``: the viable bound of the joint limits (:mod:`.viable_bound`) keeps the next
state able to stop before it at ``max_deceleration`` and approaches it over ``horizon``, never
asking for more than that deceleration (obstacles move, witness points jump between features:
an obstacle that jumps in is braked back out at that deceleration). A self pair found inside the
safety distance when it enters the rows (a start) is held where it is and not let closer, its
floor following it out (:meth:`floor_of`): never asked to jump apart. One row per
pair, the ``max_pairs`` closest: the QP's size is fixed; unused rows are relaxed. A pair left
out for that budget has no row (no bound at all that cycle), and may enter it already
binding, with no last bound to relax from: the torques step. ``max_pairs`` should therefore
cover the pairs that come close at once, each row costing a larger QP: the default leaves room
for those of a hand going round a ball, its hand and finger hulls, with none left out
(test_collision_avoidance.py). The pairs are ranked by distance: ranked by how much their
bounds bind, they swapped in and out of the rows from one cycle to the next, the torques
stepping at each swap. A pair entering the influence zone at the speeds the horizon allows
gets a bound that does not bind yet (a fast pair enters early, while it can still stop gently
before the safety distance: :meth:`pair_limits`): its torques change continuously.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from .collision_relaxation import LET_GO, RowRelaxation
from .generic_constraint import GenericConstraint
from .row_capacity import row_capacity
from .viable_bound import ViableBound
from ..common.task_base import ActivationState
from ..robot.collision_geometry import CollisionGeometry, make_shape
from ..robot.collision_pairs import SAMPLES
from ..utils.logger import get_logger

_LOG = get_logger('collision')
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
#: the longest an obstacle's pose is carried on along its velocity [s], by default
EXTRAPOLATION = 0.1


def _skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _cross(a, b):
    """Return the cross product of two 3-vectors (numpy's cross costs far more on these)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


class RowArrays(NamedTuple):
    """A collision constraint's rows written: pairs, distances, count; the last cycle's rows."""

    sel: np.ndarray
    seld: np.ndarray
    written: np.ndarray
    lastC: np.ndarray
    last_sel: np.ndarray
    last_seld: np.ndarray


class CollisionAvoidanceConstraint(RowRelaxation, GenericConstraint):
    def __init__(self, name: str, srdf: str | None = None, influence_distance: float = 0.1,
                 safety_distance: float = 0.02, max_pairs: int = 16,
                 max_deceleration: float = 5.0, horizon: float = 0.1, package_dirs=None,
                 max_extrapolation: float = EXTRAPOLATION, pair_samples: int = SAMPLES,
                 max_depth: float = 0.1):
        super().__init__(name)
        self.srdf, self.package_dirs = srdf, package_dirs
        if int(pair_samples) < 0:
            raise ValueError(f"constraint '{name}': pair_samples must be >= 0")
        #: postures sampled to leave out the self pairs never or always in contact (0: none)
        self.pair_samples = int(pair_samples)
        if not (np.isfinite(max_extrapolation) and max_extrapolation >= 0.0):
            raise ValueError(f"constraint '{name}': max extrapolation must be finite and >= 0")
        #: the longest a pose is carried on along its velocity [s] (see move_obstacle)
        self.max_extrapolation = float(max_extrapolation)
        for what, value in (('influence distance', influence_distance),
                            ('max deceleration', max_deceleration), ('horizon', horizon),
                            ('max depth', max_depth)):
            if not (np.isfinite(value) and value > 0.0):
                raise ValueError(f"constraint '{name}': {what} must be finite and > 0")
        if not (np.isfinite(safety_distance) and 0.0 <= safety_distance < influence_distance):
            raise ValueError(f"constraint '{name}': safety distance must be in [0, influence "
                             'distance)')
        if int(max_pairs) < 1:
            raise ValueError(f"constraint '{name}': max_pairs must be >= 1")
        # [influence distance, safety distance, horizon, max deceleration, the bound a row is
        # let go at (-LET_GO x max deceleration)]: read by the kernels
        self.settings = np.array([influence_distance, safety_distance, horizon,
                                  max_deceleration, -LET_GO * max_deceleration], dtype=float)
        self.max_pairs = int(max_pairs)
        #: the deepest an obstacle may go into the robot's moving bodies, added or moved [m]
        self.max_depth = float(max_depth)
        self.geometry: CollisionGeometry | None = None
        self._pending: dict = {}  # obstacles added before the robot is known
        self._moving: dict = {}  # name -> (pose, velocity, time of the pose): moved each cycle
        self._kernels = None  # the compiled cycle's (constraint/collision_kernel.py), if any
        self._leaving: list = []  # (row, bound) of removed obstacles' pairs, relaxing away
        # rows written in the last cycle: pairs _sel[:_m] at distances _seld[:_m] (an array: an
        # attribute set every cycle would tell the compiled cycle the constraint changed)
        self._written = np.zeros(1, dtype=np.int64)
        self._sel, self._seld = np.zeros(0, dtype=np.int64), np.zeros(0)
        # pairs found inside the safety distance as they entered the rows (a count), and the
        # count and time of the last line that named them
        self.found = np.zeros(1, dtype=np.int64)
        self._told = (0, -np.inf)

    influence_distance = property(lambda self: float(self.settings[0]),
                                  doc='pairs closer than this [m] are watched')
    safety_distance = property(lambda self: float(self.settings[1]),
                               doc='the least distance kept between bodies [m]')
    horizon = property(lambda self: float(self.settings[2]),
                       doc='time over which the distance approaches the safety distance [s]')
    max_deceleration = property(lambda self: float(self.settings[3]),
                                doc='the largest closing deceleration asked [m/s^2]')

    @property
    def last_pairs(self) -> list[tuple[str, str, float]]:
        """Return the pairs of the last cycle's rows: (body, body, distance), closest first."""
        geom = self.geometry
        return [(*geom.names_of(int(k)), float(d))
                for k, d in zip(self._sel[:self._m], self._seld[:self._m])]

    _m = property(lambda self: int(self._written[0]))

    def row_arrays(self) -> RowArrays:
        """
        Return the arrays of the rows written, which the kernels read and write in place.

        The pairs and distances of the rows written this cycle and how many (``written[0]``),
        and the last cycle's rows (see :meth:`hold_departed`). Made anew with ``C`` (resize).
        """
        return RowArrays(self._sel, self._seld, self._written, self._lastC, self._last_sel,
                         self._last_seld)

    def explain(self) -> str:
        """Name the pairs of the last cycle's rows within the safety distance, closest first."""
        inside = [p for p in self.last_pairs if p[2] < self.safety_distance]
        if not inside:
            return 'no pair within the safety distance'
        told = ', '.join(f'{a} {-d * 1e3:.1f} mm into {b}' if d < 0.0 else
                         f'{a} and {b} {d * 1e3:.1f} mm apart' for a, b, d in inside[:3])
        more = f' and {len(inside) - 3} more' if len(inside) > 3 else ''
        return f'{told}{more} (safety distance {self.safety_distance * 1e3:g} mm)'

    def update(self, current_time: float, dt: float) -> None:
        """Recompute the rows: by the kernels straight away in the steady state."""
        if (self._kernels is not None and self.state is ActivationState.ACTIVATED
                and self.compute_begin_cb is None and self.compute_end_cb is None
                and not self._moving):
            self.robot.update_terms()  # (the compiled cycle's pass: nothing to do)
            if self._by_kernels(dt):
                if self.found[0] != self._told[0]:
                    self._tell_found(current_time)
                return
        super().update(current_time, dt)
        if self.found[0] != self._told[0]:
            self._tell_found(current_time)

    def _tell_found(self, now: float) -> None:
        """Name the pairs found inside the safety distance, held there (1 line/s at most)."""
        if now - self._told[1] < 1.0:
            return
        self._told = (int(self.found[0]), now)
        _LOG.warning("constraint '%s': self pairs found inside the safety distance are held where "
                     'they are, not let closer: %s', self.name, self.explain())

    def _by_kernels(self, dt: float) -> bool:
        """Fill the rows by the kernels (the robot's terms are this state's); False: failed."""
        try:
            m = self._written[0] = self._kernels.update(dt)
        except RuntimeError as exc:  # views no longer laid out as read: Python from now on
            _LOG.error("constraint '%s': %s; its rows are computed in Python from now on",
                       self.name, exc)
            self._kernels = None
            return False
        if self._leaving:
            self._leave(m, dt)
        return True

    def use_kernels(self, kernels) -> None:
        """Fill the rows by ``kernels`` (the compiled cycle's), or in Python again (None)."""
        self._kernels = kernels

    # ------------------------------------------------------------------ obstacles
    def add_obstacle(self, name: str, shape: str, size, pose=None, frame=None) -> None:
        """
        Add (or replace) a sphere, box, cylinder or capsule at ``pose`` (world or ``frame``).

        ValueError, nothing changed, for one that would go more than ``max_depth`` into the
        robot's moving bodies (:meth:`_refuse_deep`).
        """
        if self.geometry is None:
            make_shape(shape, size)  # refused now, not at configuration
            self._pending[name] = (shape, size, pose, frame)
        else:
            self._refuse_deep(name, make_shape(shape, size), pose, frame)
            self.geometry.add_obstacle(name, shape, size, pose, frame)

    def _refuse_deep(self, name: str, shape, pose, frame) -> None:
        """
        Raise ValueError if the shape at ``pose`` goes more than ``max_depth`` into the robot.

        No obstacle is first seen that deep: it crossed the influence distance on its way in.
        Kept, its rows would ask bodies deep inside it to come out at max_deceleration, each at
        its witness point: a ball of 100 m round the lwr's base (metres for centimetres) threw
        its joints at the torque limits before the QP had no solution.
        """
        if self.robot is not None and self.robot.is_initialized():
            depth, link = self.geometry.depth_into_robot(self.robot.data, shape, pose, frame,
                                                         self.max_depth)
            if depth > self.max_depth:
                raise ValueError(f"it would go {depth * 1e3:.0f} mm into the robot ('{link}'), "
                                 f'deeper than max_depth ({self.max_depth * 1e3:.0f} mm)')

    def move_obstacle(self, name: str, pose, frame=None, velocity=None, at=None) -> None:
        """
        Move an obstacle; ``velocity``: its linear velocity (world), when it moves on.

        ``at``: the time [s, the controller's clock] of ``pose``, for an obstacle in the world
        with a velocity: each cycle then places it where it has moved since (at most
        ``max_extrapolation`` s on), so that a late or sparse pose (a perception's, a topic on a
        busy machine) is not taken for the obstacle's position now. Past that it stands still
        until its next pose: set it to the poses' period plus their latency. Longer carries an
        obstacle that stopped on further (its speed times the extra time); shorter leaves a
        moving obstacle standing still before each pose, which then jumps it on and steps the
        torques (test_obstacle_updates.py). Refused as :meth:`add_obstacle` refuses, where it
        was left.
        """
        if self.geometry is not None and name in self.geometry.obstacles:
            shape = self.geometry.geom_model.geometryObjects[self.geometry.obstacles[name]]
            self._refuse_deep(name, shape.geometry, pose, frame)
        self._moving.pop(name, None)
        if at is not None and velocity is not None and frame is None:
            self._moving[name] = (np.array(pose, dtype=float), np.asarray(velocity, float), at)
        if self.geometry is None:
            shape, size, _, _ = self._pending[name]
            self._pending[name] = (shape, size, pose, frame)
        else:
            self.geometry.move_obstacle(name, pose, frame, velocity)

    def remove_obstacle(self, name: str) -> None:
        """
        Remove an obstacle; the bounds it set last cycle relax away (``_leave``).

        Without that, an arm held off an obstacle by its rows, its task pulling into it, lurched
        the moment it was removed, its torques stepping in one cycle (test_ros_obstacles.py's
        ball).
        """
        self._moving.pop(name, None)
        if self.geometry is None:
            del self._pending[name]
            return
        geom = self.geometry
        index = geom.obstacles.get(name)
        self.kept_bounds()  # the rows' pairs numbered as now (an obstacle added: renumbered)
        for i in range(self._m):
            k = int(self._sel[i])
            if index is not None and k >= 0 and index in geom.pairs[k]:
                self._leaving.append((self.C[i].copy(), float(self.lb[i])))
        geom.remove_obstacle(name)

    def obstacle_names(self) -> list[str]:
        return sorted(self._pending if self.geometry is None else self.geometry.obstacles)

    # ------------------------------------------------------------------ rows
    def rows(self) -> int:
        return self.max_pairs

    def resize(self, layout) -> None:
        super().resize(layout)
        m = self.max_pairs
        self._room, self._vel, self._out = np.zeros(m), np.zeros(m), np.zeros(m)
        self._out_safe = np.zeros(m)
        self._sel, self._seld = np.zeros(m, dtype=np.int64), np.zeros(m)
        self._written[0] = 0
        # the rows of the last cycle, their pairs and distances (see hold_departed)
        self._lastC, self._last_m = np.zeros((m, self.robot.model.nv)), 0  # (acc. columns)
        self._last_sel, self._last_seld = np.full(m, -1, dtype=np.int64), np.zeros(m)
        # per pair: its last bound, and the cycle it was set in (see _update_constraint_function)
        self._kept_version, self._cycle = None, np.zeros(1, dtype=np.int64)
        self._kept_names: list = []
        self._bound = ViableBound(m)
        self._bound.set_acceleration(self.max_deceleration)
        robot = self.robot
        self.capacity = row_capacity(robot)
        if self.geometry is None or self.geometry.model is not robot.model:
            self.geometry = CollisionGeometry(robot, self.srdf, self.package_dirs,
                                              samples=self.pair_samples,
                                              near=self.safety_distance)
            _LOG.info("constraint '%s': %s", self.name, self.geometry.pair_summary)
            for name, args in self._pending.items():
                self.geometry.add_obstacle(name, *args)
            self._pending = {}

    def pair_limits(self, closing: np.ndarray) -> np.ndarray:
        """
        Return the distance under which each pair may need a row, from its closing-speed bound.

        A pair has a row within the influence distance, or while it could not stop gently
        before the safety distance: room < h c + c |c| / A at its closing speed c (see
        _update_constraint_function); c is at most ``closing``.
        """
        h, A = self.horizon, self.max_deceleration
        return np.maximum(self.influence_distance,
                          self.safety_distance + h * closing + closing * closing / A)

    def _point(self, joint: int, p: np.ndarray):
        """(Jacobian 3 x nv, velocity, acceleration at nu_dot = 0) of a point fixed on a joint."""
        robot = self.robot
        nv = robot.model.nv
        if joint == 0:
            return np.zeros((3, nv)), np.zeros(3), np.zeros(3)
        data = robot.data
        J6 = pin.getJointJacobian(robot.model, data, joint, _LWA)
        M = data.oMi[joint]
        r = p - M.translation
        J = J6[:3] - _skew(r) @ J6[3:]
        R = M.rotation
        rl = R.T @ r
        v, a = data.v[joint], data.a[joint]  # local frame; a: the drift (computeAllTerms)
        w = v.angular
        acc = R @ (a.linear + _cross(a.angular, rl) + _cross(w, v.linear + _cross(w, rl)))
        return J, J @ robot.buffers.v_pin, acc

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        robot = self.robot
        robot.update_terms()  # the joints' placements, Jacobians and drifts of this state
        geom = self.geometry
        for name, (pose, velocity, at) in self._moving.items():
            moved = pose.copy()
            moved[:3, 3] += velocity * min(max(current_time - at, 0.0), self.max_extrapolation)
            geom.move_obstacle(name, moved, None, velocity)
        if self._kernels is not None and self._by_kernels(dt):
            return
        C, lb, ub = self.C, self.lb, self.ub
        self.kept_bounds()  # (the last rows' pairs numbered as the geometry's now)
        last = self._last_m = int(self._written[0])
        self._lastC[:last], self._last_sel[:last] = C[:last, self.layout.acc], self._sel[:last]
        self._last_seld[:last] = self._seld[:last]
        C.fill(0.0)
        lb.fill(-np.inf)
        ub.fill(np.inf)
        h, A = self.horizon, self.max_deceleration
        pairs = geom.closest(robot.data, self.pair_limits)
        rows = []
        for d, k, p1, p2, n in pairs:
            ja, jb = geom.joints_of(k)
            Ja, va, aa = self._point(ja, p1)
            Jb, vb, ab = self._point(jb, p2)
            oa, ob = geom.velocity_of(k)  # a moving obstacle closes in too
            if oa is not None:
                va = va + oa
            if ob is not None:
                vb = vb + ob
            closing = -float(n @ (vb - va))
            room = d - self.safety_distance
            # watched within the influence distance, or while it could not stop gently before
            # the safety distance (over the horizon, then at A): a fast pair enters early, with
            # a bound that does not bind yet
            if d < self.influence_distance or room < h * closing + closing * abs(closing) / A:
                rows.append((room, closing, n @ (Jb - Ja), float(n @ (ab - aa)), k, d))
            if len(rows) == self.max_pairs:
                break
        for i, r in enumerate(rows):
            self._sel[i], self._seld[i] = r[4], r[5]
        self._cycle[0] += 1
        self._write_rows(rows, dt)
        m = self._written[0] = self.hold_departed(len(rows), dt)
        if self._leaving:
            self._leave(m, dt)

    def floor_of(self, k: int, d: float, cycle: int) -> float:
        """
        Return the least distance pair ``k``, at distance ``d``, is held at this cycle; keep it.

        The safety distance, or less for a self pair found inside it: one that enters the rows
        there (a start, a pair back from beyond ``max_pairs``) is held where it is, not pushed
        apart (at up to max_deceleration: a jump the joints' limits may not allow, the QP then
        infeasible); while it keeps its row its floor follows it out, never back in, up to the
        safety distance. An obstacle's pairs keep the safety distance: an obstacle moves, and one
        seen late or sparsely jumps in; it is braked back out (safety first: held where found,
        a sparsely posed ball went further into the hand at each pose). The
        kernels (``constraint/collision_kernel.py``) keep the same floors.
        """
        safety = self.settings[1]
        if d >= safety or not self.geometry.is_self_pair(k):
            floor = safety  # (an obstacle: it moves, and may jump in; braked back out)
        elif self._kept_cycle[k] == cycle - 1:  # it had a row: its floor, or further out
            floor = min(max(self._floor[k], d), safety)
        else:
            floor = d
            self.found[0] += 1
        self._floor[k] = floor
        return floor

    def _write_rows(self, rows: list, dt: float) -> None:
        """Write this cycle's rows and their bounds (each relaxing at A / horizon at most)."""
        if not rows:
            return
        C, lb = self.C, self.lb
        room, vel, out = self._room, self._vel, self._out
        room.fill(np.inf)
        vel.fill(0.0)
        drift = np.zeros(len(rows))
        acc = self.layout.acc
        kept, when, cycle = self._kept, self._kept_cycle, self._cycle[0]
        for i, (_, closing, row, dr, k, d) in enumerate(rows):
            C[i, acc] = row
            room[i], vel[i], drift[i] = d - self.floor_of(k, d, cycle), closing, dr
        h = max(self.horizon, dt)
        self._bound.upper(room, vel, dt, h, out, one_step=False)
        m = len(rows)
        lb[:m] = -out[:m] - drift  # closing acceleration at most out: d_ddot >= -out
        self._cycle_safe = None  # (_rate_limited's, this cycle's)
        for i in range(m):
            k = rows[i][4]
            if when[k] == cycle - 1:
                lb[i] = self._rate_limited(i, lb[i], kept[k], room, vel, drift, dt, h, m)
            # never more than the joints can give the pair (see row_capacity)
            lb[i] = min(lb[i], float(np.abs(rows[i][2]) @ self.capacity))
            kept[k], when[k] = lb[i], cycle
