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
Regularisation of the whole reduced variable.

|| nu_dot + k_d nu ||^2 + || w / (0.1 m g) ||^2 with a small weight: accelerations in their own
units, contact wrenches in tenths of the robot's weight m g (``column_weights``), so that the
default weight stays negligible next to the tasks on a 1 kg arm and on a 100 kg humanoid alike.
In newtons, 1e-4 ||w||^2 outweighed a weight-1 CoM task on the 90 kg Talos (its CoM sagged 13 cm);
with a whole m g as the unit the wrench block of the Hessian (1e-4 in the solver's units) is too
flat for ProxQP, which then ran out of iterations on a quadruped switching a foot off.

It makes the QP strictly convex (unique solution) and, through the damping gain k_d, makes
redundant (null-space) motion decay instead of drifting. With k_d = 0 it is plain acceleration
regularisation. It never biases a task at rest (nu = 0 gives a zero target).
"""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask

WRENCH_UNIT = 0.1  # share of the robot's weight that the regularisation counts as one wrench unit


class RegularisationTask(GenericTask):
    def __init__(
        self, name: str = 'GlobalRegularisation', weight: float = 1e-4, damping: float = 1.0
    ):
        super().__init__(name)
        self.set_weight(weight)
        self.damping = float(damping)

    def rows(self) -> int:
        return self.layout.nx

    def set_damping(self, damping: float) -> None:
        if not damping >= 0.0:
            raise ValueError('regularisation damping must be >= 0')
        self.damping = float(damping)

    def resize(self, layout) -> None:
        super().resize(layout)
        self.E[:] = np.eye(layout.nx)
        self.diagonal_columns = slice(0, layout.nx)
        # per-variable factor on the weight: 1 for accelerations, 1 / (0.1 m g)^2 for wrenches
        self.column_weights = np.ones(layout.nx)
        self.column_weights[layout.wrench] = (WRENCH_UNIT * layout.weight_scale()) ** -2

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        lay = self.layout
        if self.damping:
            np.multiply(self.robot.buffers.v_pin, -self.damping, out=self.f[lay.acc])
        else:
            self.f[lay.acc] = 0.0
