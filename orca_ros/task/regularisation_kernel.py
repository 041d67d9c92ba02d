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
The regularisation's compiled form: its row kernel and its lowering.

:func:`regularisation_rows` computes what :class:`.regularisation_task.RegularisationTask`
computes in Python: the damping term ``f = -d nu`` on its diagonal rows (``d``: the table's
parameter).
"""

from __future__ import annotations

from .regularisation_task import RegularisationTask
from ..common.lowered import Lowered, offset_in, REG
from ..utils.jit import njit


@njit
def regularisation_rows(d, v_pin, f):
    """Write -d nu into f (zero where d is zero: no -0.0 * inf)."""
    for i in range(v_pin.shape[0]):
        f[i] = v_pin[i] * -d if d != 0.0 else 0.0


class RegularisationLowered(Lowered):
    """The regularisation in the fill kernel's table: its damping is the table's parameter."""

    kind = REG
    lowers = RegularisationTask

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        tables.tab[k, 3] = offset_in(self.obj.f, plan.diag_f)

    def refresh(self) -> None:
        self.set_par(self.obj.damping)
