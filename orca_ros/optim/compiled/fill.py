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
Every lowered object's rows in one kernel call, driven by a table (one row per object).

Each kind's row kernel lives beside its concept (``task/cartesian_kernel.py``,
``constraint/joint_limit_kernel.py``...): this kernel only dispatches on the table.

``tab[k]`` = [kind, on, a, b, joint]: ``a`` indexes the kind's records (Cartesian records,
joint-task records, limit pairs), ``b`` is where its output goes (a row of the plan's E, an offset
in the diagonal tasks' f, a row of the constraint matrix M, a joint box); ``par[k]`` holds its
scalars (horizon, damping). Pinocchio's joint placements, velocities and drifts are read as three
arrays over Data's own storage (:func:`orca_ros.robot.data_views.data_views`).
"""

from __future__ import annotations

from ...common.lowered import (
    ACCELERATION, CART, COM, JOINT, MOM, POSITION, REG, TORQUE, VELOCITY,
)
from ...constraint.joint_limit_kernel import (
    acceleration_box, position_box, torque_rows, velocity_box,
)
from ...task.cartesian_kernel import cartesian_rows
from ...task.com_kernel import com_rows
from ...task.joint_acceleration_kernel import joint_rows
from ...task.momentum_kernel import momentum_rows
from ...task.regularisation_kernel import regularisation_rows
from ...utils.jit import njit


@njit
def fill(dt, ws):
    """
    Fill the rows of every lowered object that computes (``tab[k, 1]``), on the workspace.

    (The workspace is the argument, not its ~36 arrays: see :func:`.assembly.assemble`.)
    """
    J, oMi, vj, aj, q, v, v_pin = ws.J, ws.oMi, ws.vj, ws.aj, ws.q, ws.v, ws.v_pin
    T, t0, E, f, dg_f, M, lo, hi, nx = ws.T, ws.t0, ws.E, ws.f, ws.dg_f, ws.M, ws.lo, ws.hi, ws.nx
    box_lb, box_ub, cart, cart_sup, jrec = ws.box_lb, ws.box_ub, ws.cart, ws.cart_sup, ws.jrec
    lims, pacc, tab, par, tmp = ws.lims, ws.pacc, ws.tab, ws.par, ws.tmp
    com, vcom, Jcom, body, crec = ws.com, ws.vcom, ws.Jcom, ws.body, ws.crec
    Ag, hg, dhg, mrec = ws.Ag, ws.hg, ws.dhg, ws.mrec
    for k in range(tab.shape[0]):
        if tab[k, 1] == 0:
            continue
        kind, a, b = tab[k, 0], tab[k, 2], tab[k, 3]
        if kind == CART:
            j = tab[k, 4]
            R = oMi[j, 0:9].reshape(3, 3).T  # column-major storage
            cartesian_rows(cart[a], R, oMi[j, 9:12], vj[j], aj[j], J, cart_sup[a], E, f, b, dt,
                           tmp)
        elif kind == JOINT:
            n = q.shape[0]
            joint_rows(jrec[a], n, q, v, dg_f[b: b + n], dt, tmp)
        elif kind == REG:
            regularisation_rows(par[k, 0], v_pin, dg_f[b: b + v_pin.shape[0]])
        elif kind == TORQUE:
            torque_rows(T, t0, lims[a], M, lo, hi, b, nx)
        elif kind == POSITION:
            position_box(q, v, lims[a, 0], lims[a, 1], pacc[a], dt, par[k, 0], box_lb[b],
                         box_ub[b])
        elif kind == VELOCITY:
            velocity_box(v, lims[a], dt, par[k, 0], box_lb[b], box_ub[b])
        elif kind == COM:
            com_rows(crec[a], com, vcom, Jcom, oMi, vj, aj, body, E, f, b, dt, tmp)
        elif kind == MOM:
            momentum_rows(mrec[a], Ag, hg, dhg, par[k, 0], E, f, b, dt, tmp)
        elif kind == ACCELERATION:
            acceleration_box(lims[a], box_lb[b], box_ub[b])
