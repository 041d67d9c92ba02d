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
The joints' capacity for a row of accelerations: each coordinate's at its torque limit alone.

A bound on a row of joint accelerations that asks for more than the joints' torques allow makes
the QP infeasible; :func:`row_capacity` is what such a bound is capped at (the collision rows:
:mod:`.collision_avoidance`, and their kernels in ``constraint/collision_kernel.py``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

#: a capacity for the base's coordinates (moved by contacts, not torques): no cap
_UNCAPPED = 1e9


def row_capacity(robot) -> np.ndarray:
    """
    Return each coordinate's acceleration at its torque limit alone, tau_max_i / M_ii (nv).

    A row n . (J_p2 - J_p1) nu_dot >= lb can be met at most up to sum_i |row_i| tau_max_i / M_ii
    (each joint at its limit, gravity and coupling aside): a bound above that asks the joints
    for what they cannot give, and the QP has no solution. That happens where the pair's
    distance is stationary in the joints (a UR5's flange block at its closest to the first wrist
    link: the row ~0, while the bound asked for a separation, and the wrist spun to its
    velocity limit). The bound is capped there. Computed at configuration
    (the start posture's inertia); joints without a torque limit, and a floating base's
    coordinates, are not capped.
    """
    model = robot.model
    data = model.createData()
    M = pin.crba(model, data, robot.get_configuration())
    nb = model.nv - robot.get_nr_of_degrees_of_freedom()
    cap = np.full(model.nv, _UNCAPPED)
    tau = robot.get_joint_torque_limits()
    inertia = np.diag(M)[nb:]
    ok = np.isfinite(tau) & (tau > 0.0) & (inertia > 0.0)
    cap[nb:][ok] = np.minimum(tau[ok] / inertia[ok], _UNCAPPED)
    return cap
