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
The momentum task's compiled form: its record, its row kernel, its lowering.

:func:`momentum_rows` computes what :class:`.momentum_task.MomentumTask` computes in Python:
``E = A_g / m``, ``f = (h_dot_ref + PI(h_ref - h) - A_g_dot nu) / m``. The record holds eight
blocks of 6 values (offsets below, in blocks); the table's parameter is 1 / m.
"""

from __future__ import annotations

from .momentum_task import MomentumTask
from ..common.lowered import Lowered, MOM, offset_in
from ..servo.pid_kernel import pid_command
from ..utils.jit import njit

M_H_REF, M_HD_REF, M_KP, M_KI, M_KD, M_WINDUP, M_INTEGRAL, M_ERR = range(8)
SIZE = 48


@njit
def momentum_rows(rec, Ag, h, drift, inv_m, E, f, row, dt, tmp):
    """
    One momentum task: E[row:row+6] = A_g / m, f = (h_dot_ref + PI(h_ref - h) - A_g_dot nu) / m.

    h = A_g nu, A_g and the drift A_g_dot nu: the robot's CentroidalMomentum terms of this state
    (Pinocchio's dccrba; the reference path's very numbers). MomentumTask's maths.
    """
    err = rec[M_ERR * 6: M_ERR * 6 + 6]
    derr, cmd = tmp[0:6], tmp[6:12]
    for i in range(6):
        err[i] = rec[M_H_REF * 6 + i] - h[i]
        derr[i] = 0.0  # (no derivative term: the momentum's rate is not measured)
    pid_command(rec, M_KP * 6, M_KI * 6, M_KD * 6, M_WINDUP * 6, M_INTEGRAL * 6, err, derr, 6,
                dt, cmd)
    for i in range(6):
        f[row + i] = ((rec[M_HD_REF * 6 + i] + cmd[i]) - drift[i]) * inv_m
        for c in range(Ag.shape[1]):
            E[row + i, c] = Ag[i, c] * inv_m


class MomentumLowered(Lowered):
    """A momentum task in the fill kernel's table: its record in ``tables.mrec``."""

    kind = MOM
    lowers = MomentumTask

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        self.keep_servoed('mom', {'h_ref': 6 * M_H_REF, 'hd_ref': 6 * M_HD_REF, 'err': 6 * M_ERR},
                          (6 * M_KP, 6 * M_KI, 6 * M_KD, 6 * M_WINDUP, 6 * M_INTEGRAL))
        tables.tab[k, 3] = offset_in(self.obj.E, plan.E)
        self.refresh()

    def refresh(self) -> None:
        self.set_par(1.0 / self.obj.robot.get_total_mass())  # (its rows are per unit of mass)

    def rebind_model(self) -> None:
        self.refresh()
