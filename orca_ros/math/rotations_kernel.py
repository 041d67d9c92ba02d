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
Rotations in the compiled cycle (numba): the rotation vector of a matrix, as Pinocchio's log3.

The reference path calls ``pin.log3`` (:func:`.rotations.orientation_error`); the Cartesian
task's kernel calls :func:`log3`, the same scheme written out, so both paths give the same error
to round-off (``test_compiled_cycle.py`` compares them over random and near-pi rotations).
"""

from __future__ import annotations

import math

import numpy as np

from ..utils.jit import njit

_EPS = np.finfo(np.float64).eps
_PREC = _EPS ** (1.0 / 3.0)  # Pinocchio's Taylor precision of degree 2


@njit
def _theta_axis(i0, val, N, axis):
    """Angle and unit axis near pi from the diagonal entry ``i0`` (the largest); axis in place."""
    i1, i2 = (i0 + 1) % 3, (i0 + 2) % 3
    s = math.sqrt(val + _EPS + _EPS * _EPS) * (1.0 if N[i2, i1] >= N[i1, i2] else -1.0)
    axis[i0] = s / 2.0
    axis[i1] = 1.0 / (2.0 * s) * (N[i1, i0] + N[i0, i1])
    axis[i2] = 1.0 / (2.0 * s) * (N[i2, i0] + N[i0, i2])
    w = 1.0 / (2.0 * s) * (N[i2, i1] - N[i1, i2])
    norm = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    for k in range(3):
        axis[k] /= norm
    return 2.0 * math.atan2(norm, w)


@njit
def log3(R, out, N):
    """
    Rotation vector of R into out[0:3], by the scheme of the pinned Pinocchio's log3.

    R re-orthonormalised (into N, 3x3 scratch); theta from acos away from 0 and pi, from its
    expansion near them; the vector from the skew part scaled by theta / sin(theta), except near
    pi, where the axis comes from the largest diagonal entry.
    """
    n0 = math.sqrt(R[0, 0] ** 2 + R[1, 0] ** 2 + R[2, 0] ** 2)
    n1 = math.sqrt(R[0, 1] ** 2 + R[1, 1] ** 2 + R[2, 1] ** 2)
    for r in range(3):
        N[r, 0] = R[r, 0] / n0
        N[r, 1] = R[r, 1] / n1
    N[0, 2] = N[1, 0] * N[2, 1] - N[2, 0] * N[1, 1]
    N[1, 2] = N[2, 0] * N[0, 1] - N[0, 0] * N[2, 1]
    N[2, 2] = N[0, 0] * N[1, 1] - N[1, 0] * N[0, 1]
    N[0, 0] = N[1, 1] * N[2, 2] - N[2, 1] * N[1, 2]
    N[1, 0] = N[2, 1] * N[0, 2] - N[0, 1] * N[2, 2]
    N[2, 0] = N[0, 1] * N[1, 2] - N[1, 1] * N[0, 2]
    tr = N[0, 0] + N[1, 1] + N[2, 2]
    cos_value = (tr - 1.0) / 2.0
    if cos_value < -1.0 + _PREC:  # near pi
        v0, v1, v2 = 2.0 * N[0, 0] - tr + 1.0, 2.0 * N[1, 1] - tr + 1.0, 2.0 * N[2, 2] - tr + 1.0
        if v0 >= v1:
            i0, val = (0, v0) if v0 >= v2 else (2, v2)
        else:
            i0, val = (1, v1) if v1 >= v2 else (2, v2)
        theta = _theta_axis(i0, val, N, out)
        for k in range(3):
            out[k] *= theta
        return
    acos_expansion = math.sqrt(2.0 * (1.0 - cos_value) + _EPS * _EPS)
    if tr <= 3.0 - _PREC:
        theta = math.acos(cos_value) if tr >= -1.0 + _PREC else math.pi - acos_expansion
    else:
        theta = acos_expansion
    a0 = 0.5 * (N[2, 1] - N[1, 2])
    a1 = 0.5 * (N[0, 2] - N[2, 0])
    a2 = 0.5 * (N[1, 0] - N[0, 1])
    if theta >= _PREC:
        t = theta / math.sin(theta)
    else:
        n2 = a0 * a0 + a1 * a1 + a2 * a2
        t = 1.0 + n2 / 6.0 + n2 * n2 * 3.0 / 40.0
    out[0], out[1], out[2] = t * a0, t * a1, t * a2
