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
The collision kernels' screening: which pairs' distances coal must compute this cycle.

:func:`screen` places the geometries, bounds each pair's closing speed from its bodies' relative
velocity field (:func:`_closing`), and keeps the pairs whose bounding spheres and capsules are
within the distance that may matter, unless their last distance, less how far their bodies have
moved since (:func:`_moved`), is still beyond it. Every bound is conservative: the pairs left out
have no row in the reference path either (``test_collision_kernels.py``).
"""

from __future__ import annotations

import math

from ..utils.jit import njit

#: a pair's distance is computed again when its bound from the last one is this close to its limit
#: [m] (GJK's own tolerance is far below)
SEEN_MARGIN = 1e-4


@njit
def screen(ws):
    """
    Keep the pairs that may come within reach; return how many.

    They are listed in ``cand`` and marked in ``active``; ``changed[0]``: whether the marks
    changed since the last cycle.

    ``gsphere[g]`` = [centre in the geometry's frame (3), radius]; ``limit[k]``: the distance
    under which pair k may need a row, from the bound on its closing speed (:func:`_closing`;
    the reference's ``pair_limits``). A pair is kept when its bounding spheres are closer than
    that, unless its last computed distance ``seen[k, 0]``, less how far any point of either
    body has moved since (the centre's displacement plus the radius times the rotation's change,
    ``seen[k, 1:]``), is still beyond it (with SEEN_MARGIN): its distance now is then too, as the
    reference finds; and unless their bounding capsules (``gcaps[g]`` = [end, end, radius] in the
    geometry's frame, ``segs`` its ends in the world) are: a link is held closely by a capsule,
    loosely by a sphere.
    """
    oMg, gsphere, centres, gvc = ws.oMg, ws.gsphere, ws.centres, ws.gvc
    pairs, limit, seen, active = ws.pairs, ws.limit, ws.seen, ws.active
    gcaps, segs, gjoint, oMi, vj, gvel = ws.gcaps, ws.segs, ws.gjoint, ws.oMi, ws.vj, ws.gvel
    influence, safety, h, A = ws.settings[0], ws.settings[1], ws.settings[2], ws.settings[3]
    _place(oMg, oMi, ws.place, gjoint)
    for g in range(gjoint.shape[0]):
        for r in range(3):
            s = oMg[g, 9 + r]
            e0, e1 = s, s
            for c in range(3):
                R = oMg[g, r + 3 * c]
                s += R * gsphere[g, c]
                e0 += R * gcaps[g, c]
                e1 += R * gcaps[g, 3 + c]
            centres[g, r], segs[g, r], segs[g, 3 + r] = s, e0, e1
        # the velocity field: the centre's velocity, the angular velocity (world)
        j = gjoint[g]
        if j == 0:
            gvc[g, 0], gvc[g, 1], gvc[g, 2] = gvel[g, 0], gvel[g, 1], gvel[g, 2]
            gvc[g, 3] = gvc[g, 4] = gvc[g, 5] = 0.0
            continue
        v0, v1, v2, w0, w1, w2 = vj[j, 0], vj[j, 1], vj[j, 2], vj[j, 3], vj[j, 4], vj[j, 5]
        x0, x1, x2 = (centres[g, 0] - oMi[j, 9], centres[g, 1] - oMi[j, 10],
                      centres[g, 2] - oMi[j, 11])
        # R v, R w (joint-local velocities; R column-major), then + w x (centre - origin)
        u0 = oMi[j, 0] * v0 + oMi[j, 3] * v1 + oMi[j, 6] * v2
        u1 = oMi[j, 1] * v0 + oMi[j, 4] * v1 + oMi[j, 7] * v2
        u2 = oMi[j, 2] * v0 + oMi[j, 5] * v1 + oMi[j, 8] * v2
        o0 = oMi[j, 0] * w0 + oMi[j, 3] * w1 + oMi[j, 6] * w2
        o1 = oMi[j, 1] * w0 + oMi[j, 4] * w1 + oMi[j, 7] * w2
        o2 = oMi[j, 2] * w0 + oMi[j, 5] * w1 + oMi[j, 8] * w2
        gvc[g, 0] = gvel[g, 0] + u0 + o1 * x2 - o2 * x1
        gvc[g, 1] = gvel[g, 1] + u1 + o2 * x0 - o0 * x2
        gvc[g, 2] = gvel[g, 2] + u2 + o0 * x1 - o1 * x0
        gvc[g, 3], gvc[g, 4], gvc[g, 5] = o0, o1, o2
    n = 0
    ws.changed[0] = 0
    for k in range(ws.npairs):
        a, b = pairs[k, 0], pairs[k, 1]
        was = active[a, b]
        active[a, b] = False
        c = _closing(gvc, centres, gsphere, a, b)
        limit[k] = max(influence, safety + h * c + c * c / A)
        d2 = 0.0
        for r in range(3):
            d2 += (centres[a, r] - centres[b, r]) ** 2
        if math.sqrt(d2) - gsphere[a, 3] - gsphere[b, 3] >= limit[k]:
            ws.changed[0] |= was
            continue
        if seen[k, 0] - _moved(oMg, centres, gsphere, a, seen, k, 1) \
                - _moved(oMg, centres, gsphere, b, seen, k, 13) >= limit[k] + SEEN_MARGIN:
            ws.counts[1] += 1
            ws.changed[0] |= was
            continue  # (False for a NaN distance)
        if _segment_distance(segs, a, b) - gcaps[a, 6] - gcaps[b, 6] >= limit[k]:
            ws.changed[0] |= was
            continue
        ws.changed[0] |= not was
        active[a, b] = True
        ws.cand[n] = k
        n += 1
    ws.counts[0] += n
    return n


@njit
def _place(oMg, oMi, place, gjoint):
    """Place the geometries: oMg = oMi[joint] * placement (as updateGeometryPlacements)."""
    for g in range(gjoint.shape[0]):
        j = gjoint[g]
        for r in range(3):
            t = oMi[j, 9 + r]
            for c in range(3):
                t += oMi[j, r + 3 * c] * place[g, 9 + c]
                e = 0.0
                for i in range(3):
                    e += oMi[j, r + 3 * i] * place[g, i + 3 * c]
                oMg[g, r + 3 * c] = e
            oMg[g, 9 + r] = t


@njit
def _closing(gvc, centres, gsphere, a, b):
    """
    Bound the speed at which pair (a, b)'s distance can shrink (the reference's closing_bound).

    W = V_b - V_a, the bodies' relative velocity field: the rate is n . W(p1) and W(p1) is
    within |w_b - w_a| r_a of W at a's centre (likewise at b's): the smaller of the two bounds.
    """
    dw0, dw1, dw2 = gvc[b, 3] - gvc[a, 3], gvc[b, 4] - gvc[a, 4], gvc[b, 5] - gvc[a, 5]
    dw = math.sqrt(dw0 * dw0 + dw1 * dw1 + dw2 * dw2)
    x0, x1, x2 = (centres[a, 0] - centres[b, 0], centres[a, 1] - centres[b, 1],
                  centres[a, 2] - centres[b, 2])
    # at a's centre: v_b + w_b x (c_a - c_b) - v_a; at b's: v_b - v_a + w_a x (c_a - c_b)
    d0, d1, d2 = gvc[b, 0] - gvc[a, 0], gvc[b, 1] - gvc[a, 1], gvc[b, 2] - gvc[a, 2]
    wb0, wb1, wb2 = gvc[b, 3], gvc[b, 4], gvc[b, 5]
    wa0, wa1, wa2 = gvc[a, 3], gvc[a, 4], gvc[a, 5]
    at_a = math.sqrt((d0 + wb1 * x2 - wb2 * x1) ** 2 + (d1 + wb2 * x0 - wb0 * x2) ** 2
                     + (d2 + wb0 * x1 - wb1 * x0) ** 2) + dw * gsphere[a, 3]
    at_b = math.sqrt((d0 + wa1 * x2 - wa2 * x1) ** 2 + (d1 + wa2 * x0 - wa0 * x2) ** 2
                     + (d2 + wa0 * x1 - wa1 * x0) ** 2) + dw * gsphere[b, 3]
    return min(at_a, at_b)


@njit
def _moved(oMg, centres, gsphere, g, seen, k, at):
    """
    Bound on how far any point of geometry g moved since seen[k, at:at + 12] = [centre, R].

    A point u from the centre moves by |(R1 - R0) u| <= |R1 - R0|_2 |u|, and for rotations
    |R1 - R0|_2 = 2 sin(angle / 2) = |R1 - R0|_F / sqrt(2) (R0^T R1 - I is normal).
    """
    dc = 0.0
    for r in range(3):
        dc += (centres[g, r] - seen[k, at + r]) ** 2
    dr = 0.0
    for i in range(9):
        dr += (oMg[g, i] - seen[k, at + 3 + i]) ** 2
    return math.sqrt(dc) + gsphere[g, 3] * math.sqrt(0.5 * dr)


@njit
def _segment_distance(segs, a, b):
    """Return the distance between segments a and b (segs[g] = [end, end], world; Ericson's)."""
    u0, u1, u2 = segs[a, 3] - segs[a, 0], segs[a, 4] - segs[a, 1], segs[a, 5] - segs[a, 2]
    w0, w1, w2 = segs[b, 3] - segs[b, 0], segs[b, 4] - segs[b, 1], segs[b, 5] - segs[b, 2]
    r0, r1, r2 = segs[a, 0] - segs[b, 0], segs[a, 1] - segs[b, 1], segs[a, 2] - segs[b, 2]
    uu, ww = u0 * u0 + u1 * u1 + u2 * u2, w0 * w0 + w1 * w1 + w2 * w2
    f = w0 * r0 + w1 * r1 + w2 * r2
    s = t = 0.0
    if uu <= 1e-18:  # a point
        if ww > 1e-18:
            t = min(max(f / ww, 0.0), 1.0)
    else:
        c = u0 * r0 + u1 * r1 + u2 * r2
        if ww <= 1e-18:
            s = min(max(-c / uu, 0.0), 1.0)
        else:
            uw = u0 * w0 + u1 * w1 + u2 * w2
            den = uu * ww - uw * uw
            if den > 0.0:  # (parallel: any s; 0)
                s = min(max((uw * f - c * ww) / den, 0.0), 1.0)
            t = (uw * s + f) / ww
            if t < 0.0:
                t = 0.0
                s = min(max(-c / uu, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((uw - c) / uu, 0.0), 1.0)
    return math.sqrt((r0 + u0 * s - w0 * t) ** 2 + (r1 + u1 * s - w1 * t) ** 2
                     + (r2 + u2 * s - w2 * t) ** 2)
