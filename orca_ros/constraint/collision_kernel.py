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
Collision avoidance by kernel: what CollisionAvoidanceConstraint's update does, in two kernels.

Per cycle, around coal's distances of the pairs that may matter:

1. :func:`~.collision_screen_kernel.screen` places the geometries (Pinocchio's ``oMg``, over its
   own storage) and keeps the pairs that may come within reach (bounding spheres and capsules,
   each pair's closing-speed bound, how far its bodies moved since its last distance);
2. coal computes those pairs' distances (``computeDistances`` on the pairs marked active), which
   leaves its results in GeometryData's ``distanceResults``;
3. :func:`rows` reads the results over their storage, keeps the watched pairs closest first (at
   most ``max_pairs``), and writes each one's row n . (J_p2 - J_p1) from Data's joint Jacobians,
   and its bound from the distance's drift and the viable bound, into the constraint's arrays.

The same numbers as the reference (``CollisionAvoidanceConstraint`` in Python, the same
``computeDistance``), to rounding: ``test_collision_kernels.py``. The views on coal's results are
checked at set-up, value by value for every pair; where their layout is not the one read here
(another coal), :func:`result_view` returns None and the constraint keeps its Python update.
"""

from __future__ import annotations

import math

from numba.experimental import structref
import numpy as np
import pinocchio as pin

from .collision_avoidance import CollisionAvoidanceConstraint
from .collision_screen_kernel import screen
from .viable_bound_kernel import viable_upper
from ..robot.data_views import data_views, placement_view, RES, result_view
from ..utils.jit import entry, njit
from ..utils.struct_type import StructType


@njit
def _point_terms(jt, res, k, at, sign, oMi, vj, aj, J, sup, row):
    """
    Add sign * n . J_p to ``row``; return n . (drift acceleration of p) (0 for the world).

    p = res[k, at:at + 3] (a nearest point), n = res[k, 1:4] (the pair's normal).
    """
    if jt == 0:
        return 0.0
    n0, n1, n2 = res[k, 1], res[k, 2], res[k, 3]
    p0, p1, p2 = res[k, at], res[k, at + 1], res[k, at + 2]
    # n . (v_o + w x p) per column: n . J_lin + J_ang . (p x n)
    pxn0 = p1 * n2 - p2 * n1
    pxn1 = p2 * n0 - p0 * n2
    pxn2 = p0 * n1 - p1 * n0
    for c in range(J.shape[1]):
        if sup[jt, c]:
            row[c] += sign * (n0 * J[0, c] + n1 * J[1, c] + n2 * J[2, c]
                              + J[3, c] * pxn0 + J[4, c] * pxn1 + J[5, c] * pxn2)
    # the point's acceleration at nu_dot = 0, in the joint's frame then turned to the world:
    # a_lin + a_ang x rl + w x (v_lin + w x rl), rl = R^T (p - t)
    d0, d1, d2 = p0 - oMi[jt, 9], p1 - oMi[jt, 10], p2 - oMi[jt, 11]
    rl0 = oMi[jt, 0] * d0 + oMi[jt, 1] * d1 + oMi[jt, 2] * d2
    rl1 = oMi[jt, 3] * d0 + oMi[jt, 4] * d1 + oMi[jt, 5] * d2
    rl2 = oMi[jt, 6] * d0 + oMi[jt, 7] * d1 + oMi[jt, 8] * d2
    w0, w1, w2 = vj[jt, 3], vj[jt, 4], vj[jt, 5]
    u0 = vj[jt, 0] + w1 * rl2 - w2 * rl1
    u1 = vj[jt, 1] + w2 * rl0 - w0 * rl2
    u2 = vj[jt, 2] + w0 * rl1 - w1 * rl0
    b0, b1, b2 = aj[jt, 3], aj[jt, 4], aj[jt, 5]
    loc0 = aj[jt, 0] + b1 * rl2 - b2 * rl1 + w1 * u2 - w2 * u1
    loc1 = aj[jt, 1] + b2 * rl0 - b0 * rl2 + w2 * u0 - w0 * u2
    loc2 = aj[jt, 2] + b0 * rl1 - b1 * rl0 + w0 * u1 - w1 * u0
    return (n0 * (oMi[jt, 0] * loc0 + oMi[jt, 3] * loc1 + oMi[jt, 6] * loc2)
            + n1 * (oMi[jt, 1] * loc0 + oMi[jt, 4] * loc1 + oMi[jt, 7] * loc2)
            + n2 * (oMi[jt, 2] * loc0 + oMi[jt, 5] * loc1 + oMi[jt, 8] * loc2))


@njit
def rows(ws, n, dt, acc0):
    """
    Write the watched pairs' rows and lower bounds, closest first; return how many.

    Of the ``n`` pairs kept by :func:`screen`, whose distances coal has just computed (their
    placements and distances recorded in ``seen`` first); ``acc0``: the column of the first
    acceleration. ``sel``/``seld``: the pairs written and their distances.
    """
    res, cand, limit, order, pairs, gjoint, gvel = (ws.res, ws.cand, ws.limit, ws.order, ws.pairs,
                                                    ws.gjoint, ws.gvel)
    oMi, vj, aj, J, sup, v_pin = ws.oMi, ws.vj, ws.aj, ws.J, ws.sup, ws.v_pin
    C, lb, ub, seen = ws.C, ws.lb, ws.ub, ws.seen
    influence, safety, h, A = ws.settings[0], ws.settings[1], ws.settings[2], ws.settings[3]
    ws.cycle[0] += 1
    cycle = ws.cycle[0]
    relax = A / max(h, dt) * dt
    last = ws.written[0]  # the rows of the last cycle, kept for the pairs that leave them
    nv = ws.row.shape[0]  # (their accelerations' columns: the others are 0)
    for i in range(last):
        ws.lastsel[i], ws.lastseld[i] = ws.sel[i], ws.seld[i]
        for c in range(nv):
            ws.lastC[i, c] = C[i, acc0 + c]
    C[:, :] = 0.0
    lb[:] = -np.inf
    ub[:] = np.inf
    m = 0
    for i in range(n):
        k = cand[i]
        seen[k, 0] = res[k, 0]
        for side in range(2):
            g, at = pairs[k, side], 1 + 12 * side
            for r in range(3):
                seen[k, at + r] = ws.centres[g, r]
            for e in range(9):
                seen[k, at + 3 + e] = ws.oMg[g, e]
        d = res[k, 0]
        if not (d < limit[k] and math.isfinite(res[k, 1] + res[k, 2] + res[k, 3])):
            continue  # (a NaN: no row, as the reference)
        at = m  # the pairs within their limit, by distance (stable: as the reference)
        while at > 0 and res[order[at - 1], 0] > d:
            order[at] = order[at - 1]
            at -= 1
        order[at] = k
        m += 1
    row = ws.row
    out = 0
    for i in range(m):
        if out == C.shape[0]:
            break
        k = order[i]
        d = res[k, 0]
        ga, gb = pairs[k, 0], pairs[k, 1]
        row[:] = 0.0
        drift = _point_terms(gjoint[gb], res, k, 7, 1.0, oMi, vj, aj, J, sup, row)
        drift -= _point_terms(gjoint[ga], res, k, 4, -1.0, oMi, vj, aj, J, sup, row)
        rate = 0.0  # n . (v_p2 - v_p1)
        for c in range(row.shape[0]):
            rate += row[c] * v_pin[c]
        for r in range(3):
            rate += res[k, 1 + r] * (gvel[gb, r] - gvel[ga, r])
        closing = -rate
        room = d - safety
        if d < influence or room < h * closing + closing * abs(closing) / A:
            for c in range(row.shape[0]):
                C[out, acc0 + c] = row[c]
            floor = safety  # (CollisionAvoidanceConstraint.floor_of)
            if d < safety and gb < ws.nrobot:  # a self pair (obstacles keep the safety distance)
                if ws.kept_cycle[k] == cycle - 1:
                    floor = min(max(ws.floor[k], d), safety)
                else:
                    floor = d
                    ws.found[0] += 1
            ws.floor[k] = floor
            bound = -viable_upper(d - floor, closing, A, dt, max(h, dt), False) - drift
            if ws.kept_cycle[k] == cycle - 1:
                # the braking margin's term tightens at A / horizon per second at most; what
                # viability and the horizon ask, at once (RowRelaxation._rate_limited)
                if bound > ws.kept[k] + relax:
                    safe = -viable_upper(d - floor, closing, A, dt, max(h, dt), False,
                                         False) - drift
                    bound = max(safe, ws.kept[k] + relax)
                if bound < ws.kept[k] - relax:
                    bound = min(ws.kept[k] - relax, A - drift)
            cap = 0.0  # never more than the joints can give the pair (collision_avoidance's
            for c in range(row.shape[0]):  # row_capacity)
                cap += abs(row[c]) * ws.capacity[c]
            if bound > cap:
                bound = cap
            lb[out] = bound
            ws.kept[k], ws.kept_cycle[k] = bound, cycle
            ws.sel[out] = k
            ws.seld[out] = d
            out += 1
    # a pair that had a row and has none now keeps its last one, its bound relaxing, until it
    # lets go (CollisionAvoidanceConstraint.hold_departed)
    for i in range(last):
        k = ws.lastsel[i]
        if k < 0 or ws.kept_cycle[k] != cycle - 1:
            continue
        bound = ws.kept[k] - relax
        if bound > ws.settings[4] and out < C.shape[0]:
            for c in range(nv):
                C[out, acc0 + c] = ws.lastC[i, c]
            lb[out] = bound
            ws.kept[k], ws.kept_cycle[k] = bound, cycle
            ws.sel[out], ws.seld[out] = k, ws.lastseld[i]
            out += 1
    return out


FIELDS = (
    # Pinocchio: the geometries' placements (GeometryData), the joints' placements, velocities,
    # drifts and Jacobians (Data), the joints' supports, the velocity
    'oMg', 'oMi', 'vj', 'aj', 'J', 'sup', 'v_pin',
    # the geometries: joint, placement on it, bounding sphere [centre, radius] and capsule [ends,
    # radius], velocity (moving obstacles);
    # the pairs [first, second] and how many, the robot's geometries (the obstacles' follow)
    'gjoint', 'place', 'gsphere', 'gcaps', 'gvel', 'pairs', 'npairs', 'nrobot',
    # per cycle: sphere centres and capsule ends, velocity fields [centre's, angular], each
    # pair's limit, the kept pairs (list and mask), what was last seen of each, coal's results,
    # their order, one row
    'centres', 'segs', 'gvc', 'limit', 'cand', 'active', 'changed', 'seen', 'res', 'order',
    'row',
    # out: the pairs written and their distances; the constraint's settings and rows; the
    # distances computed and skipped (their last one, less the bodies' motion, beyond reach)
    'sel', 'seld', 'settings', 'C', 'lb', 'ub', 'counts',
    # each pair's last bound and the cycle it was set in (bounds relax at A / horizon at most),
    # its floor (the least distance it is held at), the pairs found inside their safety
    # distance (a count), and the cycle's count
    'kept', 'kept_cycle', 'floor', 'found', 'cycle',
    # each coordinate's acceleration at its torque limit alone (a bound's cap)
    'capacity',
    # the rows written (their count) and those of the last cycle: rows, pairs, distances
    'written', 'lastC', 'lastsel', 'lastseld',
)


@structref.register
class CollisionWorkspaceType(StructType):
    """Its fields' types: see struct_type."""


class CollisionWorkspace(structref.StructRefProxy):
    """The arrays of one constraint's kernels (fields: :data:`FIELDS`)."""


structref.define_proxy(CollisionWorkspace, CollisionWorkspaceType, list(FIELDS))


@njit
def _construct(*fields):
    """Make the workspace in compiled code (cached on disk; see workspace.make_workspace)."""
    return CollisionWorkspace(*fields)


class CollisionKernels:
    """The kernels of one CollisionAvoidanceConstraint, on its geometry and the robot's Data."""

    def __init__(self, constraint):
        self.constraint = constraint
        self._robot_terms: tuple = (None,)  # (Data, its views, the joints' supports)
        self._bind()

    @staticmethod
    def unavailable_reason(constraint) -> str | None:
        """Why the kernels cannot read this constraint's geometry (None: they can)."""
        geom, robot = constraint.geometry, constraint.robot
        # placed first: coal's distance objects keep state from call to call, and a first call
        # on a new GeometryData's unset placements left NaN in it (NaN rows after an obstacle's
        # removal in test_ros_obstacles.py)
        pin.updateGeometryPlacements(robot.model, robot.data, geom.geom_model, geom.geom_data)
        if placement_view(geom.geom_data, geom.geom_model.ngeoms) is None:
            return "Pinocchio's geometry placements are not laid out as the kernels read them"
        if len(geom.geom_model.collisionPairs) and result_view(geom.geom_model,
                                                               geom.geom_data) is None:
            return "coal's distance results are not laid out as the kernels read them"
        return None

    def _bind(self) -> None:
        """Take the views and make the workspace (again after the geometry or Data changed)."""
        con = self.constraint
        geom, robot = con.geometry, con.robot
        model, data = robot.model, robot.data
        gm, gd = geom.geom_model, geom.geom_data
        ng, npairs = gm.ngeoms, len(gm.collisionPairs)
        pin.updateGeometryPlacements(model, data, gm, gd)  # (see unavailable_reason)
        oMg = placement_view(gd, ng)
        res = result_view(gm, gd) if npairs else np.zeros((1, RES))
        # the robot's Data and model: checked and read again only when they are new (an
        # obstacle's addition or removal rebinds in the control cycle)
        if self._robot_terms[0] is not data:
            views = data_views(model, data)
            sup = np.zeros((model.njoints, model.nv), dtype=np.bool_)
            for jt in range(1, model.njoints):
                for s in model.supports[jt]:
                    if s > 0:
                        jm = model.joints[s]
                        sup[jt, jm.idx_v: jm.idx_v + jm.nv] = True
            self._robot_terms = (data, views, sup)
        _, views, sup = self._robot_terms
        if oMg is None or res is None or views is None:
            self._robot_terms = (None,)
            raise RuntimeError(CollisionKernels.unavailable_reason(con)
                               or "Pinocchio's Data is not laid out as the kernels read it")
        gsphere = np.zeros((ng, 4))
        gsphere[:, :3], gsphere[:, 3] = geom.sphere_centre, geom.sphere_radius
        pairs = np.zeros((max(1, npairs), 2), dtype=np.int64)
        pairs[:npairs] = np.array(geom.pairs, dtype=np.int64).reshape(-1, 2)
        size = max(1, npairs)
        self.counts = np.zeros(2, dtype=np.int64)  # distances computed, skipped (since bound)
        # the pairs coal computes: none until screened (then those that changed, when they do)
        self.active, self.changed = np.zeros((ng, ng), dtype=np.bool_), np.zeros(1, np.bool_)
        gd.deactivateAllCollisionPairs()
        kept, when, floor, cycle = con.kept_bounds()
        rows_of = con.row_arrays()
        self.ws = _construct(
            oMg, views[0], views[1], views[2], data.J, sup, robot.buffers.v_pin,
            np.array(geom.joint, dtype=np.int64), geom.placement, gsphere, geom.capsule,
            geom.velocity, pairs, npairs, geom.n_robot, np.zeros((ng, 3)), np.zeros((ng, 6)),
            np.zeros((ng, 6)), np.zeros(size), np.zeros(size, dtype=np.int64),
            self.active, self.changed, np.full((size, 25), np.nan), res,
            np.zeros(size, dtype=np.int64), np.zeros(model.nv), rows_of.sel, rows_of.seld,
            con.settings, con.C, con.lb, con.ub, self.counts, kept, when, floor, con.found, cycle,
            con.capacity,
            rows_of.written, rows_of.lastC, rows_of.last_sel, rows_of.last_seld,
        )
        self._screen = entry(screen, self.ws)
        self._rows = entry(rows, self.ws, 0, 1e-3, 0)
        self._acc0 = con.layout.acc.start
        self._bound = (geom.version, data, con.C)

    def update(self, dt: float) -> int:
        """Fill the constraint's rows for this cycle (the joints' terms are Data's); return m."""
        con = self.constraint
        geom, robot = con.geometry, con.robot
        bound = self._bound
        # (the row arrays are made anew with C: resize)
        if geom.version != bound[0] or robot.data is not bound[1] or con.C is not bound[2]:
            self._bind()
        ws = self.ws
        n = self._screen(ws)  # (the geometries placed too)
        if n:  # the kept pairs' distances, in one call
            gm, gd = geom.geom_model, geom.geom_data
            if self.changed[0]:
                gd.setActiveCollisionPairs(gm, self.active, True)
            pin.computeDistances(gm, gd)
        return self._rows(ws, n, dt, self._acc0)


def attach_kernels(constraints, in_python: list, why: dict) -> None:
    """Give the collision constraints updated in Python their kernels (distances stay coal's)."""
    for obj in constraints:
        if isinstance(obj, CollisionAvoidanceConstraint):
            obj.use_kernels(None)
            if obj not in in_python or obj.geometry is None:
                continue
            reason = CollisionKernels.unavailable_reason(obj)
            if reason is None:
                obj.use_kernels(CollisionKernels(obj))
                reason = 'its distances by coal; their screening and its rows by kernel'
            why[obj.name] = reason
