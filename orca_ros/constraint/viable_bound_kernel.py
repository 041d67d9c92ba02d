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
The viable bound's kernel (numba): :meth:`.viable_bound.ViableBound.upper` for one limit.

The largest acceleration towards a limit that keeps the next state viable (a stop within the
room is still possible braking at A), approaches over the horizon and keeps the braking margin
from shrinking faster than its time constant: the reference method's formula for one scalar,
for the compiled cycle's joint limits and collision rows.
"""

from __future__ import annotations

import math

import numpy as np

from .viable_bound import FAR, MARGIN_SHARE
from ..utils.jit import njit


@njit
def viable_upper(room, v, acc, dt, h, one_step, margin=True):
    """Return the largest admissible acceleration towards one limit (as ViableBound.upper)."""
    if room >= FAR:
        return np.inf
    R = room
    dt2 = dt * dt
    a = R - v * dt
    b = 2.0 * dt * v + acc * dt2
    c = v * v - 2.0 * acc * a
    disc = b * b - 4.0 * dt2 * c
    stop = v * (-1.0 / dt)
    if disc < 0.0:
        d = stop
    else:
        d = max((math.sqrt(disc) - b) * (0.5 / dt2), stop)
    e = (R - h * v) * (2.0 / (h * h))
    d = min(d, e)
    spare = acc * R - 0.5 * v * v  # A s: the braking margin (ViableBound.upper's f)
    if margin and v > 0.0 and spare > 0.0:  # it shrinks at most with the time constant h / 2
        d = min(d, spare / (MARGIN_SHARE * h * v) - acc)
    d = max(d, -acc)
    if one_step:
        return min(a * (2.0 / dt2), d)
    return d
