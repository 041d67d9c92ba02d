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
The centre-of-mass task's compiled form: its record, its row kernel, its lowering.

:func:`com_rows` computes what :class:`.com_task.CoMTask` computes in Python: ``E = J_com``,
``f = a_ref + PID(p_ref - p, v_ref - v) - bias``, the bias from every body's drift. The record
holds nine blocks of 3 values (offsets below, in blocks).
"""

from __future__ import annotations

from .com_task import CoMTask
from ..common.lowered import COM, Lowered, offset_in
from ..servo.pid_kernel import pid_command
from ..utils.jit import njit

C_P_REF, C_V_REF, C_A_REF, C_KP, C_KI, C_KD, C_WINDUP, C_INTEGRAL, C_ERR = range(9)
SIZE = 27


@njit
def com_rows(rec, com, vcom, Jcom, oMi, vj, aj, body, E, f, row, dt, tmp):
    """
    One CoM task: E[row:row+3] = Jcom, f = a_ref + PID(p_ref - p, v_ref - v) - bias.

    The bias (the CoM's acceleration at zero joint acceleration) from every body's drift in
    Data (``aj``, left by computeAllTerms): sum m (R (a + dw x c + w x (v + w x c))) / m_total,
    with ``body[j]`` = [mass, lever] of joint j's body and ``body[0, 0]`` the total mass.
    """
    b0 = b1 = b2 = 0.0
    for j in range(1, oMi.shape[0]):
        m = body[j, 0]
        if m == 0.0:
            continue
        cx, cy, cz = body[j, 1], body[j, 2], body[j, 3]
        vx, vy, vz, wx, wy, wz = vj[j, 0], vj[j, 1], vj[j, 2], vj[j, 3], vj[j, 4], vj[j, 5]
        ax, ay, az, dx, dy, dz = aj[j, 0], aj[j, 1], aj[j, 2], aj[j, 3], aj[j, 4], aj[j, 5]
        # velocity of the body's CoM (joint axes), then its classical acceleration
        ux, uy, uz = vx + wy * cz - wz * cy, vy + wz * cx - wx * cz, vz + wx * cy - wy * cx
        px = ax + dy * cz - dz * cy + wy * uz - wz * uy
        py = ay + dz * cx - dx * cz + wz * ux - wx * uz
        pz = az + dx * cy - dy * cx + wx * uy - wy * ux
        # rotate into the world: R is stored column-major in oMi[j, 0:9]
        b0 += m * (oMi[j, 0] * px + oMi[j, 3] * py + oMi[j, 6] * pz)
        b1 += m * (oMi[j, 1] * px + oMi[j, 4] * py + oMi[j, 7] * pz)
        b2 += m * (oMi[j, 2] * px + oMi[j, 5] * py + oMi[j, 8] * pz)
    total = body[0, 0]
    err = rec[C_ERR * 3: C_ERR * 3 + 3]
    derr = tmp[0:3]
    for i in range(3):
        err[i] = rec[C_P_REF * 3 + i] - com[i]
        derr[i] = rec[C_V_REF * 3 + i] - vcom[i]
    cmd = tmp[3:6]
    pid_command(rec, C_KP * 3, C_KI * 3, C_KD * 3, C_WINDUP * 3, C_INTEGRAL * 3, err, derr, 3, dt,
                cmd)
    bias = (b0 / total, b1 / total, b2 / total)
    for i in range(3):
        f[row + i] = (rec[C_A_REF * 3 + i] + cmd[i]) - bias[i]
        for c in range(Jcom.shape[1]):
            E[row + i, c] = Jcom[i, c]


class CoMLowered(Lowered):
    """A CoM task in the fill kernel's table: its record in ``tables.crec``."""

    kind = COM
    lowers = CoMTask

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        self.keep_servoed(
            'com', {'p_ref': 3 * C_P_REF, 'v_ref': 3 * C_V_REF, 'a_ref': 3 * C_A_REF,
                    'err': 3 * C_ERR},
            (3 * C_KP, 3 * C_KI, 3 * C_KD, 3 * C_WINDUP, 3 * C_INTEGRAL))
        tables.tab[k, 3] = offset_in(self.obj.E, plan.E)

    def refresh(self) -> None:
        task = self.obj
        if not task.has_desired():  # hold the CoM where it is when the task first computes
            task.robot.update_terms()
            task.set_desired(task.robot.data.com[0])
