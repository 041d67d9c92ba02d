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
The joint limits' compiled form: their row kernels and their lowering.

Each kernel computes what its constraint in :mod:`.joint_limit_constraints` computes in Python:
the torque limits as rows of the constraint matrix (``lo - tau_0 <= T x <= hi - tau_0``); the
viable position limits, the velocity limits over the horizon and the acceleration limits as
bounds on the joint accelerations (a joint box). A limit's (lower, upper) pair lives in
``tables.lims``, the position limits' braking accelerations in ``tables.pacc``.
"""

from __future__ import annotations

import numpy as np

from .joint_limit_constraints import (
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)
from .viable_bound import FAR
from .viable_bound_kernel import viable_upper
from ..common.lowered import ACCELERATION, Lowered, offset_in, POSITION, TORQUE, VELOCITY
from ..utils.jit import njit


@njit
def torque_rows(T, t0, lim, M, lo, hi, row, nx):
    """Rows ``row``... of M = T and their bounds lim - tau_0 (after the nx box bounds)."""
    for i in range(T.shape[0]):
        for c in range(T.shape[1]):
            M[row + i, c] = T[i, c]
        lo[nx + row + i] = lim[0, i] - t0[i]
        hi[nx + row + i] = lim[1, i] - t0[i]


@njit
def position_box(q, v, lo, hi, acc, dt, horizon, lb, ub):
    """Viable joint position limits as bounds on the joint accelerations (both sides)."""
    h = max(horizon, dt)
    for i in range(q.shape[0]):
        ub[i] = viable_upper(min(hi[i] - q[i], FAR), v[i], acc[i], dt, h, True)
        lb[i] = -viable_upper(min(q[i] - lo[i], FAR), -v[i], acc[i], dt, h, True)


@njit
def velocity_box(v, lim, dt, horizon, lb, ub):
    """Velocity limits reached over the horizon (at least dt) as bounds on the accelerations."""
    h = max(horizon, dt)
    for i in range(v.shape[0]):
        lb[i] = (lim[0, i] - v[i]) * (1.0 / h)
        ub[i] = (lim[1, i] - v[i]) * (1.0 / h)


@njit
def acceleration_box(lim, lb, ub):
    """Write the acceleration limits into the bounds as they are."""
    for i in range(lb.shape[0]):
        lb[i] = lim[0, i]
        ub[i] = lim[1, i]


class LimitLowered(Lowered):
    """A limit constraint: its (lower, upper) pair lives in the tables (``limits`` views)."""

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        self.a = tables.take('lims')
        tables.tab[k, 2] = self.a
        self._take_limits()

    def _take_limits(self) -> None:
        lo, hi = self.obj.limits
        pair = self.tables.lims[self.a]
        pair[0], pair[1] = lo, hi
        self.obj.limits = self.src = (pair[0], pair[1])

    def refresh(self) -> None:
        if self.obj.limits is not self.src:  # set_limits made a new pair
            self._take_limits()


class TorqueLimitLowered(LimitLowered):
    kind = TORQUE
    lowers = JointTorqueLimitConstraint

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        tables.tab[k, 3] = offset_in(self.obj.C, plan.M)


class _BoxLowered(LimitLowered):
    """A limit written as a joint box (its row of the plan's box bounds), with a horizon."""

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        tables.tab[k, 3] = offset_in(self.obj.lb, plan.box_lb)

    def refresh(self) -> None:
        super().refresh()
        self.set_par(getattr(self.obj, 'horizon', 0.0))


class PositionLimitLowered(_BoxLowered):
    kind = POSITION
    lowers = JointPositionLimitConstraint
    _acc_of = None

    def refresh(self) -> None:
        super().refresh()
        acc = self.obj.max_acceleration
        if acc is not self._acc_of:  # set_max_acceleration made a new one
            self._acc_of = acc
            self.tables.pacc[self.a] = np.broadcast_to(acc, self.tables.pacc.shape[1])


class VelocityLimitLowered(_BoxLowered):
    kind = VELOCITY
    lowers = JointVelocityLimitConstraint


class AccelerationLimitLowered(_BoxLowered):
    kind = ACCELERATION
    lowers = JointAccelerationLimitConstraint
