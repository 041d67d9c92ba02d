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

``tab[k]`` = [kind, on, a, b, joint]: ``a`` indexes the kind's records (Cartesian records,
joint-task records, limit pairs), ``b`` is where its output goes (a row of the plan's E, an offset
in the diagonal tasks' f, a row of the constraint matrix M, a joint box); ``par[k]`` holds its
scalars (horizon, damping). Pinocchio's joint placements, velocities and drifts are read as three
arrays over Data's own storage (see :func:`data_views`).
"""

from __future__ import annotations

import ctypes

import numpy as np

from .kernels import cartesian_rows, com_rows, joint_rows, momentum_rows, position_box
from ...utils.jit import njit

CART, JOINT, REG, TORQUE, POSITION, VELOCITY, ACCELERATION, COM, MOM = range(9)
TAB = 5  # columns of tab


def _view(first: np.ndarray, count: int, width: int) -> np.ndarray:
    """(count, width) float64 array over the memory that starts at ``first``."""
    buf = (ctypes.c_double * (count * width)).from_address(first.__array_interface__['data'][0])
    return np.ctypeslib.as_array(buf).reshape(count, width)


def data_views(model, data):
    """
    Return Data's joint placements, velocities, drifts and accelerations with gravity, on Data.

    (oMi, v, a, a_gf): (njoints, 12) [rotation column-major, translation], then (njoints, 6) each.

    Pinocchio keeps each of them in one contiguous std::vector; the layout is checked here,
    element by element against the bindings, and None is returned where it does not hold (the
    caller then reads them one by one).
    """
    nj = model.njoints
    oMi = _view(data.oMi[0].rotation, nj, 12)
    v = _view(data.v[0].vector, nj, 6)
    a = _view(data.a[0].vector, nj, 6)
    a_gf = _view(data.a_gf[0].vector, nj, 6)
    for j in range(nj):
        if not (
            np.array_equal(oMi[j, :9], data.oMi[j].rotation.reshape(-1, order='F'))
            and np.array_equal(oMi[j, 9:], data.oMi[j].translation)
            and np.array_equal(v[j], data.v[j].vector)
            and np.array_equal(a[j], data.a[j].vector)
            and np.array_equal(a_gf[j], data.a_gf[j].vector)
        ):
            return None
        addr = data.oMi[j].rotation.__array_interface__['data'][0]
        if addr != oMi[j].__array_interface__['data'][0]:
            return None
    return oMi, v, a, a_gf


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
            d = par[k, 0]
            for i in range(v_pin.shape[0]):
                dg_f[b + i] = v_pin[i] * -d if d != 0.0 else 0.0
        elif kind == TORQUE:
            for i in range(T.shape[0]):
                for c in range(T.shape[1]):
                    M[b + i, c] = T[i, c]
                lo[nx + b + i] = lims[a, 0, i] - t0[i]
                hi[nx + b + i] = lims[a, 1, i] - t0[i]
        elif kind == POSITION:
            position_box(q, v, lims[a, 0], lims[a, 1], pacc[a], dt, par[k, 0], box_lb[b],
                         box_ub[b])
        elif kind == VELOCITY:
            h = max(par[k, 0], dt)
            for i in range(q.shape[0]):
                box_lb[b, i] = (lims[a, 0, i] - v[i]) * (1.0 / h)
                box_ub[b, i] = (lims[a, 1, i] - v[i]) * (1.0 / h)
        elif kind == COM:
            com_rows(crec[a], com, vcom, Jcom, oMi, vj, aj, body, E, f, b, dt, tmp)
        elif kind == MOM:
            momentum_rows(mrec[a], Ag, hg, dhg, par[k, 0], E, f, b, dt, tmp)
        elif kind == ACCELERATION:
            for i in range(q.shape[0]):
                box_lb[b, i] = lims[a, 0, i]
                box_ub[b, i] = lims[a, 1, i]
