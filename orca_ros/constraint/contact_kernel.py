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
The contacts' compiled form: their kinematics in one kernel, and their lowering.

:func:`contact_terms` computes the wrench Jacobians, the torque map and the existence
conditions; :class:`LoweredContacts` (a part of the compiled cycle) holds their arrays and runs
their life cycle.

What ``ProblemLayout.update`` (each contact's Jacobian, T = [M_a, -J_c,a^T], t0 = n_a), the
floating base's ``DynamicsEquationConstraint`` ([M_u, -J_c,u^T] x = -n_u) and each
``ContactExistenceCondition`` (J nu_dot = -J_dot nu - gain * (J nu, less what goes into the
surface)) compute, for point contacts (``Contact``, with or without an offset) and
``SurfaceContact``; and a surface contact's cone rows, which turn with its sole (its
``_update_constraint_function``: the faces F in world axes, F blockdiag(R^T, R^T), and the normal
row R[:, 2]). What else the contacts' rows hold (a point contact's cone, the normal force bound
that follows the activation ramp) changes only with their Python state: written by their update
on the cycles after it changed. ``ct_tab[i]`` = [joint, rows of the existence condition (3 or 6),
its first row in M, on, a surface (normal from the frame's z axis), its cone's first row in M, its
faces, its wrench's first column]; ``ct_par[i]`` = [frame rotation in its joint (9, row-major),
frame position (3), point offset in the frame (3), normal in the world (3), velocity gain];
``ct_faces[i]``: a surface's faces in the sole's frame (faces x 6).
"""

from __future__ import annotations

import numpy as np

from .contact import Contact
from .surface_wrench_contact import SurfaceContact
from ..common.lowered import offset_in
from ..common.task_base import ActivationState
from ..utils.jit import njit

CT_JOINT, CT_ROWS, CT_ROW, CT_ON, CT_Z_NORMAL, CT_CONE, CT_FACES, CT_WCOL = range(8)
CT_TAB = 8
CT_R, CT_P, CT_OFF, CT_N, CT_GAIN = 0, 9, 12, 15, 18
CT_PAR = 19

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)
_ACTIVATED = ActivationState.ACTIVATED


@njit
def point_rows(par, oMi, vj, aj, j, J, support, Jp, tmp):
    """
    Write the contact point's world Jacobian (6 x nv) into Jp.

    And its velocity (tmp[0:6]), classical bias acceleration (tmp[6:12]) and the frame's
    rotation (tmp[12:21], row-major).
    """
    nv = J.shape[1]
    R = tmp[12:21].reshape(3, 3)
    pf = tmp[21:24]
    for r in range(3):
        for c in range(3):
            R[r, c] = (oMi[j, r] * par[CT_R + c] + oMi[j, r + 3] * par[CT_R + 3 + c]
                       + oMi[j, r + 6] * par[CT_R + 6 + c])
        pf[r] = oMi[j, 9 + r] + (oMi[j, r] * par[CT_P] + oMi[j, r + 3] * par[CT_P + 1]
                                 + oMi[j, r + 6] * par[CT_P + 2])
    # frame velocity and drift at its origin (joint axes), rotated into the world
    rx, ry, rz = par[CT_P], par[CT_P + 1], par[CT_P + 2]
    w0, w1, w2 = vj[j, 3], vj[j, 4], vj[j, 5]
    b0, b1, b2 = aj[j, 3], aj[j, 4], aj[j, 5]
    lv = (vj[j, 0] + w1 * rz - w2 * ry, vj[j, 1] + w2 * rx - w0 * rz, vj[j, 2] + w0 * ry - w1 * rx)
    la = (aj[j, 0] + b1 * rz - b2 * ry, aj[j, 1] + b2 * rx - b0 * rz, aj[j, 2] + b0 * ry - b1 * rx)
    v, a = tmp[0:6], tmp[6:12]
    for r in range(3):
        v[r] = oMi[j, r] * lv[0] + oMi[j, r + 3] * lv[1] + oMi[j, r + 6] * lv[2]
        v[3 + r] = oMi[j, r] * w0 + oMi[j, r + 3] * w1 + oMi[j, r + 6] * w2
        a[r] = oMi[j, r] * la[0] + oMi[j, r + 3] * la[1] + oMi[j, r + 6] * la[2]
        a[3 + r] = oMi[j, r] * b0 + oMi[j, r + 3] * b1 + oMi[j, r + 6] * b2
    a[0] += v[4] * v[2] - v[5] * v[1]
    a[1] += v[5] * v[0] - v[3] * v[2]
    a[2] += v[3] * v[1] - v[4] * v[0]
    # the frame's LOCAL_WORLD_ALIGNED Jacobian (data.J shifted to its origin; zero off the
    # support, where data.J's columns are other branches')
    for col in range(nv):
        if not support[col]:
            for r in range(6):
                Jp[r, col] = 0.0
            continue
        k0, k1, k2 = J[3, col], J[4, col], J[5, col]
        Jp[0, col] = J[0, col] + k1 * pf[2] - k2 * pf[1]
        Jp[1, col] = J[1, col] + k2 * pf[0] - k0 * pf[2]
        Jp[2, col] = J[2, col] + k0 * pf[1] - k1 * pf[0]
        Jp[3, col], Jp[4, col], Jp[5, col] = k0, k1, k2
    # the point at the offset: r = R offset
    o0, o1, o2 = par[CT_OFF], par[CT_OFF + 1], par[CT_OFF + 2]
    if o0 != 0.0 or o1 != 0.0 or o2 != 0.0:
        q0 = R[0, 0] * o0 + R[0, 1] * o1 + R[0, 2] * o2
        q1 = R[1, 0] * o0 + R[1, 1] * o1 + R[1, 2] * o2
        q2 = R[2, 0] * o0 + R[2, 1] * o1 + R[2, 2] * o2
        for col in range(nv):  # J_lin -= skew(r) J_ang
            k0, k1, k2 = Jp[3, col], Jp[4, col], Jp[5, col]
            Jp[0, col] -= q1 * k2 - q2 * k1
            Jp[1, col] -= q2 * k0 - q0 * k2
            Jp[2, col] -= q0 * k1 - q1 * k0
        w0, w1, w2 = v[3], v[4], v[5]
        c0, c1, c2 = w1 * q2 - w2 * q1, w2 * q0 - w0 * q2, w0 * q1 - w1 * q0  # w x r
        d0, d1, d2 = a[4] * q2 - a[5] * q1, a[5] * q0 - a[3] * q2, a[3] * q1 - a[4] * q0
        e0, e1, e2 = w1 * c2 - w2 * c1, w2 * c0 - w0 * c2, w0 * c1 - w1 * c0  # w x (w x r)
        v[0] += c0
        v[1] += c1
        v[2] += c2
        a[0] += d0 + e0
        a[1] += d1 + e1
        a[2] += d2 + e2


@njit
def surface_cone(F, k, R, M, row, col):
    """Write a sole's cone in world axes: M[row:row+k, col:col+6] = F blockdiag(R^T, R^T)."""
    for r in range(k):
        for c in range(3):
            M[row + r, col + c] = F[r, 0] * R[c, 0] + F[r, 1] * R[c, 1] + F[r, 2] * R[c, 2]
            M[row + r, col + 3 + c] = F[r, 3] * R[c, 0] + F[r, 4] * R[c, 1] + F[r, 5] * R[c, 2]
    for c in range(3):  # the normal force row: the sole's z axis
        M[row + k, col + c] = R[c, 2]


@njit
def contact_terms(oMi, vj, aj, J, ct_sup, M_pin, nle, Wj, T, t0, M, lo, hi, nx, ct_tab, ct_par,
                  ct_faces, dyn_row, dyn_on, dt, tmp):
    """Every contact's Jacobian and existence rows, the torque map and the dynamics rows."""
    nv = J.shape[1]
    nb = nv - T.shape[0]
    for i in range(ct_tab.shape[0]):
        Jp = Wj[6 * i: 6 * i + 6]
        par = ct_par[i]
        point_rows(par, oMi, vj, aj, ct_tab[i, CT_JOINT], J, ct_sup[i], Jp, tmp)
        if not ct_tab[i, CT_ON]:
            continue
        if ct_tab[i, CT_Z_NORMAL]:
            surface_cone(ct_faces[i], ct_tab[i, CT_FACES], tmp[12:21].reshape(3, 3), M,
                         ct_tab[i, CT_CONE], ct_tab[i, CT_WCOL])
        m, r0 = ct_tab[i, CT_ROWS], ct_tab[i, CT_ROW]
        gain = min(par[CT_GAIN], 0.5 / dt) if dt > 0.0 else 0.0
        v, a = tmp[0:6], tmp[6:12]
        if gain > 0.0:  # drop the velocity into the surface: the surface stops it itself
            if ct_tab[i, CT_Z_NORMAL]:
                n0, n1, n2 = tmp[14], tmp[17], tmp[20]  # the frame's z axis (R row-major)
            else:
                n0, n1, n2 = par[CT_N], par[CT_N + 1], par[CT_N + 2]
            vn = n0 * v[0] + n1 * v[1] + n2 * v[2]
            if vn < 0.0:
                v[0] -= vn * n0
                v[1] -= vn * n1
                v[2] -= vn * n2
        for r in range(m):
            for c in range(nv):
                M[r0 + r, c] = Jp[r, c]
            b = -a[r]
            if gain > 0.0:
                b -= gain * v[r]
            lo[nx + r0 + r] = b
            hi[nx + r0 + r] = b
    # T = [M_a, -J_c,a^T], t0 = n_a; the floating base's rows [M_u, -J_c,u^T] x = -n_u
    nw = Wj.shape[0]
    for r in range(T.shape[0]):
        for c in range(nv):
            T[r, c] = M_pin[nb + r, c]
        for c in range(nw):
            T[r, nv + c] = -Wj[c, nb + r]
        t0[r] = nle[nb + r]
    if dyn_on and dyn_row >= 0:
        for r in range(nb):
            for c in range(nv):
                M[dyn_row + r, c] = M_pin[r, c]
            for c in range(nw):
                M[dyn_row + r, nv + c] = -Wj[c, r]
            lo[nx + dyn_row + r] = -nle[r]
            hi[nx + dyn_row + r] = -nle[r]
    return 0


def _has_callbacks(obj) -> bool:
    return obj.compute_begin_cb is not None or obj.compute_end_cb is not None


class LoweredContacts:
    """
    The layout's contacts in the compiled cycle: the arrays :func:`contact_terms` reads.

    ``owns_layout``: every contact is a point or surface contact without compute callbacks (nor
    the dynamics): the kernel then computes their kinematics, the torque map and the dynamics
    rows, their own rows (cones, normal force bounds) stay in Python and :meth:`update` runs
    their life cycle. Otherwise ProblemLayout.update and the existence conditions run in Python
    as on the reference path. Either way the finish kernel writes every contact's last wrench
    into ``ct_last`` (each contact's ``last_wrench`` is a row of it).

    ``python`` (given): the cycle's objects that run their own update; :attr:`python` is what is
    left of them, the contacts taken out; ``in_python`` (the cycle's name -> why) is updated.
    """

    def __init__(self, lay, dyn, plan, model, python: list, in_python: dict):
        contacts = list(lay.contacts)
        self.contacts, self.owns_layout, self.python = [], False, list(python)
        n = len(contacts)
        self.ct_tab = np.zeros((max(1, n), CT_TAB), dtype=np.int64)
        self.ct_par = np.zeros((max(1, n), CT_PAR))
        faces = [c.faces_local.shape[0] for c in contacts if isinstance(c, SurfaceContact)]
        self.ct_faces = np.zeros((max(1, n), max(faces, default=1), 6))
        self.ct_sup = np.zeros((max(1, n), lay.nv), dtype=np.bool_)
        self.dyn = np.array([-1, 0], dtype=np.int64)
        self.Wj = lay.wrench_jacobian if n else np.zeros((0, lay.nv))
        self._bind_wrenches(contacts)
        if not n or _has_callbacks(dyn) or any(
            type(c) not in (Contact, SurfaceContact)
            or _has_callbacks(c)
            or _has_callbacks(c.existence)
            for c in contacts
        ):
            return
        for i, c in enumerate(contacts):
            self._lower(i, c, model, plan)
        if dyn.rows():
            self.dyn[0] = offset_in(dyn.C, plan.M)
        inside = {id(c.existence) for c in contacts} | {id(dyn)}
        ids = {id(c) for c in contacts}
        left = [o for o in python if id(o) not in inside]
        self.contact_objects = [o for o in left if id(o) in ids]
        self.python = [o for o in left if id(o) not in ids]
        for c in contacts:
            in_python.pop(c.existence.name, None)
            in_python[c.name] = (
                'its rows after a change of its state (its kinematics and the cone of a sole,'
                ' which turns with it, by kernel)'
            )
        in_python.pop(dyn.name, None)
        self.contacts, self.dynamics, self.owns_layout = contacts, dyn, True
        self._seen = [None] * n  # (gain, normal) last written to ct_par
        lay.T, lay.t0 = lay.T_own, lay.t0_own

    def _lower(self, i: int, c, model, plan) -> None:
        """Write contact ``i``'s table row and parameters."""
        frame = model.frames[c.fid]
        surface = isinstance(c, SurfaceContact)
        self.ct_tab[i] = [frame.parentJoint, c.existence_rows,
                          offset_in(c.existence.C, plan.M), 0, surface,
                          offset_in(c.C, plan.M) if surface else 0,
                          c.faces_local.shape[0] if surface else 0, c.wrench_slice().start]
        if surface:
            self.ct_faces[i, : c.faces_local.shape[0]] = c.faces_local
        par = self.ct_par[i]
        par[CT_R: CT_R + 9] = frame.placement.rotation.reshape(-1)
        par[CT_P: CT_P + 3] = frame.placement.translation
        offset = getattr(c, 'offset', None)
        if offset is not None:
            par[CT_OFF: CT_OFF + 3] = offset
        for j in model.supports[frame.parentJoint]:
            if j > 0:
                jm = model.joints[j]
                self.ct_sup[i, jm.idx_v: jm.idx_v + jm.nv] = True

    def _bind_wrenches(self, contacts) -> None:
        """Make the contacts' last wrenches rows of one array (``ContactBase.record_solution``)."""
        self.ct_ws = np.array([c.wrench_slice().start for c in contacts] or [0], dtype=np.int64)
        self.ct_last = np.zeros((max(1, len(contacts)), 6))
        for i, c in enumerate(contacts):
            self.ct_last[i] = c.last_wrench
            c.last_wrench = self.ct_last[i]
        self.n_wrenches = len(contacts)

    def arrays(self) -> dict:
        """Return the workspace's contact fields (:mod:`orca_ros.optim.compiled.workspace`)."""
        return {'Wj': self.Wj, 'ct_tab': self.ct_tab, 'ct_par': self.ct_par,
                'ct_faces': self.ct_faces, 'ct_sup': self.ct_sup, 'dyn': self.dyn,
                'ct_ws': self.ct_ws, 'ct_last': self.ct_last, 'n_wrenches': self.n_wrenches}

    def switch_off(self) -> None:
        """Every contact and the dynamics rows off (the kernel's compile run writes nothing)."""
        self.ct_tab[:, CT_ON] = 0
        self.dyn[1] = 0

    def update(self, t: float, dt: float) -> None:
        """
        Run the contacts' own updates and mirror their state into the kernel's arrays.

        Each existence condition follows its contact's state and ramp; a contact's velocity gain
        and normal (they change only through their setters) are written when they changed; the
        dynamics rows follow the dynamics' ramp.
        """
        for c in self.contact_objects:
            c.update(t, dt)
        tab, par, seen = self.ct_tab, self.ct_par, self._seen
        for i, c in enumerate(self.contacts):
            ex = c.existence
            if ex.state is not c.state or ex.ramp_factor != c.ramp_factor:
                ex.state, ex.ramp_factor = c.state, c.ramp_factor  # it mirrors its contact
            tab[i, CT_ON] = c.state not in _INACTIVE
            normal = None if tab[i, CT_Z_NORMAL] else c.normal  # a surface's: its frame's z axis
            if seen[i] is None or seen[i][0] != c.velocity_gain or seen[i][1] is not normal:
                par[i, CT_GAIN] = c.velocity_gain
                if normal is not None:
                    par[i, CT_N: CT_N + 3] = normal
                seen[i] = (c.velocity_gain, normal)
        dyn = self.dynamics
        if dyn.state is not _ACTIVATED and dyn.state not in _INACTIVE:
            dyn.step_ramp(t)
        self.dyn[1] = dyn.state not in _INACTIVE
