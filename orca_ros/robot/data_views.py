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
Views on Pinocchio's and coal's own storage, as the compiled cycle's kernels read them.

Data's joint placements, velocities and drifts (:func:`data_views`), GeometryData's geometry
placements (:func:`placement_view`) and coal's distance results (:func:`result_view`) live in
C++ objects; the kernels read (and, for the placements, write) them over their storage, with no
copy per cycle. Each view is checked, value by value and address by address for every element,
before it is used; where the layout is not the one read here (another Pinocchio, another coal)
the functions return None and the caller keeps its Python path.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pinocchio as pin


def _view(first: np.ndarray, count: int, width: int) -> np.ndarray:
    """(count, width) float64 array over the memory that starts at ``first``."""
    buf = (ctypes.c_double * (count * width)).from_address(first.__array_interface__['data'][0])
    return np.ctypeslib.as_array(buf).reshape(count, width)


def data_views(model, data):
    """
    Return Data's joint placements, velocities, drifts and accelerations with gravity, on Data.

    (oMi, v, a, a_gf): (njoints, 12) [rotation column-major, translation], then (njoints, 6) each.

    Pinocchio keeps each of them in one contiguous std::vector; the layout is checked here,
    element by element against the bindings, and None is returned where it does not hold (the
    caller then reads them one by one).
    """
    nj = model.njoints
    oMi = _view(data.oMi[0].rotation, nj, 12)
    v = _view(data.v[0].vector, nj, 6)
    a = _view(data.a[0].vector, nj, 6)
    a_gf = _view(data.a_gf[0].vector, nj, 6)
    for j in range(nj):
        if not (
            np.array_equal(oMi[j, :9], data.oMi[j].rotation.reshape(-1, order='F'))
            and np.array_equal(oMi[j, 9:], data.oMi[j].translation)
            and np.array_equal(v[j], data.v[j].vector)
            and np.array_equal(a[j], data.a[j].vector)
            and np.array_equal(a_gf[j], data.a_gf[j].vector)
        ):
            return None
        addr = data.oMi[j].rotation.__array_interface__['data'][0]
        if addr != oMi[j].__array_interface__['data'][0]:
            return None
    return oMi, v, a, a_gf


RES = 10  # a result as read: distance, normal (3), nearest point 1 (3), nearest point 2 (3)


def placement_view(gd, count: int):
    """(count, 12) view on GeometryData's oMg [R column-major, p], or None if not laid out so."""
    if count == 0:
        return None
    view = _view(gd.oMg[0].rotation, count, 12)
    for g in range(count):  # (equal NaNs too: a new GeometryData's placements are not set yet)
        M = gd.oMg[g]
        if not (np.array_equal(view[g, :9], M.rotation.reshape(-1, order='F'), equal_nan=True)
                and np.array_equal(view[g, 9:], M.translation, equal_nan=True)
                and M.rotation.__array_interface__['data'][0]
                == view[g].__array_interface__['data'][0]):
            return None
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
    for k in range(n):  # (equal NaNs too: bodies placed into each other may leave some)
        r = results[k]
        got = np.concatenate(([r.min_distance], r.normal, r.getNearestPoint1(),
                              r.getNearestPoint2()))
        if not (np.array_equal(view[k], got, equal_nan=True)
                and r.normal.__array_interface__['data'][0] == start + k * stride + 8):
            return None
    return view
