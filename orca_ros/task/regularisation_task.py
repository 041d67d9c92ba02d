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

|| nu_dot + k_d nu ||^2 + || w ||^2 with a small weight.

It makes the QP strictly convex (unique solution) and, through the damping gain k_d, makes
redundant (null-space) motion decay instead of drifting. With k_d = 0 it is plain acceleration
regularisation. It never biases a task at rest (nu = 0 gives a zero target).
"""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask


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

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        lay = self.layout
        if self.damping:
            np.multiply(self.robot._v_pin, -self.damping, out=self.f[lay.acc])
        else:
            self.f[lay.acc] = 0.0
