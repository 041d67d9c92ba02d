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
Lowering: at configuration, each task and constraint the kernels know becomes packed arrays.

A kind's lowering (its record layout, its binding, its row kernel) lives beside its concept, in
a sibling ``<concept>_kernel.py`` (:mod:`orca_ros.common.lowered` says what they share); this
module lists them, sizes the records of one configuration (:class:`Tables`) and picks each
object's (:func:`lower`). Every cycle the fill kernel (:mod:`.fill`) computes the lowered
objects' rows; the objects no kernel knows yet (contacts, wrench and torque tasks, balance,
Cartesian tasks in a moving base frame, anything with compute callbacks) run their Python
update, in the same order, into the same arrays: the solve that follows is the reference path's.
"""

from __future__ import annotations

import numpy as np

from ...common.lowered import ACCELERATION, CART, COM, JOINT, MOM, POSITION, TAB, TORQUE, VELOCITY
from ...common.watched import Touched
from ...constraint import joint_limit_kernel
from ...task import (
    cartesian_kernel, com_kernel, joint_acceleration_kernel, momentum_kernel,
    regularisation_kernel,
)

#: the lowered classes, by the exact class each computes (a subclass stays in Python)
LOWERED = {
    low.lowers: low for low in (
        cartesian_kernel.CartesianLowered,
        joint_acceleration_kernel.JointLowered,
        com_kernel.CoMLowered,
        momentum_kernel.MomentumLowered,
        regularisation_kernel.RegularisationLowered,
        joint_limit_kernel.TorqueLimitLowered,
        joint_limit_kernel.PositionLimitLowered,
        joint_limit_kernel.VelocityLimitLowered,
        joint_limit_kernel.AccelerationLimitLowered,
    )
}
_LIMITS = (TORQUE, POSITION, VELOCITY, ACCELERATION)


class Tables:
    """The fill kernel's records and table, sized for the lowered objects."""

    def __init__(self, lowered, robot):
        n, nv = robot.get_nr_of_degrees_of_freedom(), robot.model.nv
        count = {kind: sum(low.kind == kind for low in lowered) for kind in range(9)}
        limited = sum(low.kind in _LIMITS for low in lowered)
        self.cart = np.zeros((max(1, count[CART]), cartesian_kernel.SIZE))
        self.cart_sup = np.zeros((max(1, count[CART]), nv), dtype=np.bool_)
        self.jrec = np.zeros((max(1, count[JOINT]), joint_acceleration_kernel.BLOCKS * n))
        self.lims = np.zeros((max(1, limited), 2, n))
        self.pacc = np.ones((max(1, limited), n))
        self.tab = np.zeros((max(1, len(lowered)), TAB), dtype=np.int64)
        self.par = np.zeros((max(1, len(lowered)), 2))
        self.tmp = np.zeros(64 + n)
        self.crec = np.zeros((max(1, count[COM]), com_kernel.SIZE))
        self.mrec = np.zeros((max(1, count[MOM]), momentum_kernel.SIZE))
        self.body = np.zeros((robot.model.njoints, 4))
        self.set_bodies(robot.model)
        self.next = {'cart': 0, 'joint': 0, 'lims': 0, 'com': 0, 'mom': 0}
        #: set when an object of this configuration (or its servo) changed an attribute
        self.watch = Touched()

    def set_bodies(self, model) -> None:
        """Each joint's body [mass, lever] (row 0: the total mass), from the model's inertias."""
        for j in range(1, model.njoints):
            inertia = model.inertias[j]
            self.body[j, 0] = inertia.mass
            self.body[j, 1:] = inertia.lever
        self.body[0, 0] = self.body[1:, 0].sum() or 1.0

    def record(self, what: str, a: int):
        """Record ``a`` of ``what`` ('cart', 'joint', 'com', 'mom')."""
        return {'cart': self.cart, 'joint': self.jrec, 'com': self.crec, 'mom': self.mrec}[what][a]

    def take(self, what: str) -> int:
        """Hand out the next record of ``what`` ('cart', 'joint', 'lims', 'com', 'mom')."""
        i = self.next[what]
        self.next[what] += 1
        return i


def lower(obj):
    """Return the kernel-side object of ``obj``, or (None, why it stays in Python)."""
    if obj.compute_begin_cb is not None or obj.compute_end_cb is not None:
        return None, 'compute callbacks'
    make = LOWERED.get(type(obj))
    if make is None:
        return None, f'{type(obj).__name__} not lowered yet'
    why = make.lowerable(obj, obj.robot)
    return (None, why) if why else (make(obj), '')
