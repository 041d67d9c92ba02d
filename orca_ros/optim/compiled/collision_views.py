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
Views on Pinocchio's geometry placements and coal's distance results, as the kernels read them.

Both live in C++ objects (GeometryData's ``oMg``, its ``distanceResults``); the collision kernels
(:mod:`.collision`) read and write them over their storage. Each view is checked before it is
used; where the layout is not the one read here (another Pinocchio, another coal) the functions
return None and the constraint keeps its Python update. The first view of each kind in a process
is checked value by value and address by address for every element (~1.8 ms on the lwr with its
63 pairs): the layout is the libraries', which do not change under a running process. Later ones
(an obstacle added or removed makes a new GeometryData, in the control cycle) are checked address
by address for every element and value by value for the first and the last (~0.2 ms).
"""

from __future__ import annotations

import ctypes

import numpy as np
import pinocchio as pin

from .fill import _view

RES = 10  # a result as read: distance, normal (3), nearest point 1 (3), nearest point 2 (3)
#: the kinds of view whose layout this process checked in full on one view
_CHECKED = set()


def _checked_values(kind: str, count: int):
    """Return the elements whose values a check of a ``kind`` view compares (all, at first)."""
    if kind in _CHECKED:
        return {0, count - 1}
    return range(count)


def placement_view(gd, count: int):
    """(count, 12) view on GeometryData's oMg [R column-major, p], or None if not laid out so."""
    if count == 0:
        return None
    view = _view(gd.oMg[0].rotation, count, 12)
    values = _checked_values('placements', count)
    start, stride = view.__array_interface__['data'][0], view.strides[0]
    for g in range(count):  # (equal NaNs too: a new GeometryData's placements are not set yet)
        M = gd.oMg[g]
        if M.rotation.__array_interface__['data'][0] != start + g * stride:
            return None
        if g in values and not (
                np.array_equal(view[g, :9], M.rotation.reshape(-1, order='F'), equal_nan=True)
                and np.array_equal(view[g, 9:], M.translation, equal_nan=True)):
            return None
    _CHECKED.add('placements')
    return view


def result_view(gm, gd):
    """
    (pairs, RES) view on GeometryData's distance results, or None if not laid out as read here.

    coal's DistanceResult keeps min_distance just before the normal and the two nearest points
    after it. Checked on this GeometryData's own results after a pass over every pair.
    """
    n = len(gm.collisionPairs)
    if n == 0:
        return None
    pin.computeDistances(gm, gd)
    results = gd.distanceResults
    first = results[0].normal
    if first.flags['OWNDATA'] or first.dtype != np.float64:
        return None  # a copy: not the results' storage
    start = first.__array_interface__['data'][0] - 8
    stride = 8 * RES
    if n > 1:
        stride = results[1].normal.__array_interface__['data'][0] - start - 8
    if stride % 8 or stride < 8 * RES:
        return None
    width = stride // 8
    buf = (ctypes.c_double * ((n - 1) * width + RES)).from_address(start)
    flat = np.ctypeslib.as_array(buf)
    view = np.lib.stride_tricks.as_strided(flat, shape=(n, RES), strides=(stride, 8))
    values = _checked_values('results', n)
    for k in range(n):  # (equal NaNs too: bodies placed into each other may leave some)
        r = results[k]
        if r.normal.__array_interface__['data'][0] != start + k * stride + 8:
            return None
        if k in values and not np.array_equal(
                view[k], np.concatenate(([r.min_distance], r.normal, r.getNearestPoint1(),
                                         r.getNearestPoint2())), equal_nan=True):
            return None
    _CHECKED.add('results')
    return view
