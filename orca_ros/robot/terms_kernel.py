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
The compiled cycle's Pinocchio pass: no more than its kernels read.

The compiled form of :meth:`.RobotModel.update_terms`.

``computeAllTerms`` computes all a controller may ask of Pinocchio: the mass matrix, the
nonlinear effects, the joints' placements, velocities, Jacobians and drifts, and also the centre
of mass and its Jacobian, the centroidal momentum matrix and the energies. Where the kernels read
only the former (no centre-of-mass task lowered, no object updated in Python), two passes give
them: ``crba`` in the world convention (the mass matrix, with the placements and the Jacobians as
by-products) and ``nonLinearEffects`` (the velocities, and the accelerations with gravity, a_gf).
The drift without gravity, a = a_gf + (R^T g, 0), is written into Data's ``a`` by kernel
(:func:`drift`, at the start of the cycle's first kernel). Cheaper than ``computeAllTerms``
by what they leave out.

:func:`matches` checks that pair against ``computeAllTerms`` on a random state, once per model;
where it does not hold (another Pinocchio), ``computeAllTerms`` runs. The robot's own cache is
left alone: an API call that needs more (a CoM, a frame's acceleration) runs ``computeAllTerms``
itself.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..utils.jit import njit

_WORLD = pin.Convention.WORLD


def two_passes(model, data, q, v) -> None:
    """Run crba (world convention) and nonLinearEffects: the mass matrix, nle, a_gf."""
    pin.crba(model, data, q, _WORLD)
    pin.nonLinearEffects(model, data, q, v)


def cycle_passes():
    """(crba, nonLinearEffects, the world convention): :func:`two_passes` for a caller inline."""
    return pin.crba, pin.nonLinearEffects, _WORLD


def matches(model, views) -> bool:
    """
    Tell whether the two passes and :func:`drift` give what computeAllTerms gives.

    On a random state, to 1e-12 of each quantity's size; ``views(data)`` returns Data's
    (oMi, v, a, a_gf) as the kernels read them (None: not laid out so).
    """
    rng = np.random.default_rng(0)
    q = pin.integrate(model, pin.neutral(model), rng.normal(0.0, 0.5, model.nv))
    v = rng.normal(0.0, 1.0, model.nv)
    full, two = model.createData(), model.createData()
    pin.computeAllTerms(model, full, q, v)
    two_passes(model, two, q, v)
    fv, tv = views(full), views(two)
    if fv is None or tv is None:
        return False
    drift(tv[0], tv[3], tv[2], model.gravity.linear.copy())
    for a, b in ((full.M, two.M), (full.nle, two.nle), (full.J, two.J), (fv[0], tv[0]),
                 (fv[1], tv[1]), (fv[2], tv[2])):
        if not np.all(np.abs(a - b) <= 1e-12 * max(1.0, np.abs(a).max())):
            return False
    return True


@njit
def drift(oMi, a_gf, a, g):
    """Write each joint's drift a = a_gf + (R^T g, 0) (Data's a, as computeAllTerms leaves it)."""
    for j in range(1, a.shape[0]):
        for c in range(3):
            s = 0.0
            for r in range(3):
                s += oMi[j, r + 3 * c] * g[r]  # R column-major: R[r, c]
            a[j, c] = a_gf[j, c] + s
        for c in range(3, 6):
            a[j, c] = a_gf[j, c]
