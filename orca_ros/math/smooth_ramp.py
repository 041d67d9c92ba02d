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
Smooth 0 -> 1 ramp used for task/constraint activation.

The quintic "smootherstep" s(x) = 10x^3 - 15x^4 + 6x^5 has zero first *and* second derivative at
both ends, so a weight following it starts and stops without a step in value, slope or curvature.
"""

from __future__ import annotations


def smooth_ramp(x: float) -> float:
    """Ramp value for normalised time x (clamped to [0, 1])."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


def smooth_ramp_derivative(x: float) -> float:
    """D smooth_ramp / dx (zero outside (0, 1))."""
    if x <= 0.0 or x >= 1.0:
        return 0.0
    return 30.0 * x * x * (1.0 - x) * (1.0 - x)
