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
The joint acceleration task's compiled form: its record, its row kernel, its lowering.

:func:`joint_rows` computes what :class:`.joint_acceleration_task.JointAccelerationTask`
computes in Python: ``f = qdd_ref + PID(q_ref - q, qd_ref - qd)`` on the task's diagonal rows.
The record holds ten blocks of n values (offsets below, in blocks).
"""

from __future__ import annotations

from .joint_acceleration_task import JointAccelerationTask
from ..common.lowered import JOINT, Lowered, offset_in
from ..servo.pid_kernel import pid_command
from ..utils.jit import njit

J_Q_REF, J_QD_REF, J_QDD_REF, J_KP, J_KI, J_KD, J_WINDUP, J_INTEGRAL, J_Q_ERR, J_QD_ERR = range(10)
BLOCKS = 10


@njit
def joint_rows(rec, n, q, v, f, dt, tmp):
    """One joint acceleration task: f = qdd_ref + PID(q_ref - q, qd_ref - qd), errors into rec."""
    qe = rec[J_Q_ERR * n: (J_Q_ERR + 1) * n]
    qde = rec[J_QD_ERR * n: (J_QD_ERR + 1) * n]
    for i in range(n):
        qe[i] = rec[J_Q_REF * n + i] - q[i]
        qde[i] = rec[J_QD_REF * n + i] - v[i]
    pid_command(
        rec, J_KP * n, J_KI * n, J_KD * n, J_WINDUP * n, J_INTEGRAL * n, qe, qde, n, dt, tmp
    )
    for i in range(n):
        f[i] = rec[J_QDD_REF * n + i] + tmp[i]


class JointLowered(Lowered):
    """A joint acceleration task in the fill kernel's table: its record in ``tables.jrec``."""

    kind = JOINT
    lowers = JointAccelerationTask

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        task = self.obj
        n = task.robot.get_nr_of_degrees_of_freedom()
        self.keep_servoed(
            'joint', {'q_ref': J_Q_REF * n, 'qd_ref': J_QD_REF * n, 'qdd_ref': J_QDD_REF * n,
                      'q_err': J_Q_ERR * n, 'qd_err': J_QD_ERR * n},
            (J_KP * n, J_KI * n, J_KD * n, J_WINDUP * n, J_INTEGRAL * n))
        tables.tab[k, 3] = offset_in(task.f, plan.diag_f)

    def refresh(self) -> None:
        if not self.obj.has_desired():
            self.obj.hold_current_position()
