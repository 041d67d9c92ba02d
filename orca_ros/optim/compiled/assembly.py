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
The plan's per-cycle assembly as one kernel: what ``CyclePlan.update`` and level 0's build do.

Row weights (selection x effective weight), the diagonal tasks' products, the relaxation of the
constraints that switched off, the merge of the joint boxes and the first level's Hessian and
gradient, on the plan's packed arrays (see ``CyclePlan``). Integer tables (``plan_tables``) say
which rows belong to what; per cycle the caller writes the effective weights and the on/off flags.
"""

from __future__ import annotations

import numpy as np

from ...utils.jit import njit

# columns of the diagonal tasks' table
D_ROW, D_N, D_COL = 0, 1, 2
# columns of the constraints' table
C_EQ, C_ROW, C_N, C_RELAXED = 0, 1, 2, 3


@njit
def assemble(ws):
    """
    Assemble the cycle's problem in place on the workspace; return 1 when soft boxes conflicted.

    ``n0`` dense rows and ``nd0`` diagonal tasks (the regularisation first) make level 0;
    ``jb``: first joint-acceleration variable, ``nj`` joints. (The workspace is the argument,
    not its arrays one by one: each array passed to a call costs a reference count taken and
    given back, atomic operations.)
    """
    E, f, w, sel, row_task, ew = ws.E, ws.f, ws.w, ws.sel, ws.row_task, ws.ew
    dg_f, dg_sel, dg_colw, dg_ws, dg_wsf = ws.dg_f, ws.dg_sel, ws.dg_colw, ws.dg_ws, ws.dg_wsf
    dg_tab, dg_ew, n0, nd0, H, g, WE = ws.dg_tab, ws.dg_ew, ws.n0, ws.nd0, ws.H, ws.g, ws.WE
    M, lo, hi, nx, ne, con_tab, con_on = ws.M, ws.lo, ws.hi, ws.nx, ws.ne, ws.con_tab, ws.con_on
    box_lb, box_ub, box_on, nsoft, jb, nj = (ws.box_lb, ws.box_ub, ws.box_on, ws.nsoft, ws.jb,
                                             ws.nj)
    # row weights
    for r in range(w.shape[0]):
        w[r] = sel[r] * ew[row_task[r]]
    # diagonal tasks: ws = selection x weight (x column weight), wsf = ws x f
    for k in range(dg_tab.shape[0]):
        r0, n = dg_tab[k, D_ROW], dg_tab[k, D_N]
        for i in range(r0, r0 + n):
            dg_ws[i] = dg_sel[i] * dg_ew[k] * dg_colw[i]
            dg_wsf[i] = dg_ws[i] * dg_f[i]
    # level 0: H = E^T W E + diag(ws), g = -E^T W f - wsf
    H[:, :] = 0.0
    g[:] = 0.0
    for r in range(n0):
        wr = w[r]
        if wr == 0.0:
            continue
        for a in range(nx):
            WE[r, a] = wr * E[r, a]
        for a in range(nx):
            wa = WE[r, a]
            if wa == 0.0:
                continue
            g[a] -= wa * f[r]
            for b in range(nx):
                H[a, b] += wa * E[r, b]
    for k in range(nd0):
        r0, n, c0 = dg_tab[k, D_ROW], dg_tab[k, D_N], dg_tab[k, D_COL]
        for i in range(n):
            H[c0 + i, c0 + i] += dg_ws[r0 + i]
            g[c0 + i] -= dg_wsf[r0 + i]
    # constraints that switched off keep their rows, relaxed (once)
    for k in range(con_tab.shape[0]):
        r0, n = con_tab[k, C_ROW], con_tab[k, C_N]
        if con_on[k]:
            con_tab[k, C_RELAXED] = 0
            continue
        if con_tab[k, C_RELAXED]:
            continue
        con_tab[k, C_RELAXED] = 1
        for i in range(r0, r0 + n):
            if con_tab[k, C_EQ]:
                M[i, :] = 0.0
                lo[nx + i] = 0.0
            else:
                lo[nx + i] = -np.inf
                hi[nx + i] = np.inf
    for i in range(ne):
        hi[nx + i] = lo[nx + i]
    # joint boxes: soft ones intersected (a conflict split in the middle), hard ones clip
    conflict = 0
    if box_lb.shape[0] == 0:
        return conflict
    first = True
    for k in range(nsoft):
        if not box_on[k]:
            continue
        for i in range(nj):
            if first:
                lo[jb + i] = box_lb[k, i]
                hi[jb + i] = box_ub[k, i]
            else:
                lo[jb + i] = max(lo[jb + i], box_lb[k, i])
                hi[jb + i] = min(hi[jb + i], box_ub[k, i])
        first = False
    if first:
        for i in range(nj):
            lo[jb + i] = -np.inf
            hi[jb + i] = np.inf
    else:
        for i in range(nj):
            if lo[jb + i] > hi[jb + i]:
                conflict = 1
                mid = 0.5 * (lo[jb + i] + hi[jb + i])
                lo[jb + i] = mid
                hi[jb + i] = mid
    for k in range(nsoft, box_lb.shape[0]):
        if not box_on[k]:
            continue
        for i in range(nj):
            lo[jb + i] = min(max(lo[jb + i], box_lb[k, i]), box_ub[k, i])
            hi[jb + i] = min(max(hi[jb + i], box_lb[k, i]), box_ub[k, i])
    return conflict
