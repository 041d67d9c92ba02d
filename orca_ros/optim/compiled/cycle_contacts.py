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
The compiled cycle's contacts: their kinematics, the torque map and the dynamics rows by kernel.

A part of :class:`.cycle.CompiledCycle` (a mixin: the same object, its own file): lowering
the layout's contacts into packed arrays at configuration, mirroring their states and
existence conditions per cycle, and the arrays of their last wrenches that the finish kernel
writes.
"""

from __future__ import annotations

import numpy as np

from . import contacts as ck
from .lowering import offset_in
from ...common.task_base import ActivationState
from ...constraint.contact import Contact
from ...constraint.surface_wrench_contact import SurfaceContact

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)
_ACTIVATED = ActivationState.ACTIVATED


def _has_callbacks(obj) -> bool:
    return obj.compute_begin_cb is not None or obj.compute_end_cb is not None


class CycleContacts:
    """The contact side of CompiledCycle (see the module)."""

    def _lower_contacts(self, lay, dyn, plan) -> None:
        """
        Take the contacts' kinematics (and the torque map, the dynamics rows) into the kernel.

        When every contact is a point or surface contact without compute callbacks; their own
        rows (cones, normal force bounds) stay in Python. Otherwise ProblemLayout.update and the
        existence conditions run in Python as on the reference path.
        """
        contacts = list(lay.contacts)
        self.contacts, self.owns_layout = [], False
        n = len(contacts)
        self.ct_tab = np.zeros((max(1, n), ck.CT_TAB), dtype=np.int64)
        self.ct_par = np.zeros((max(1, n), ck.CT_PAR))
        faces = [c.faces_local.shape[0] for c in contacts if isinstance(c, SurfaceContact)]
        self.ct_faces = np.zeros((max(1, n), max(faces, default=1), 6))
        self.ct_sup = np.zeros((max(1, n), lay.nv), dtype=np.bool_)
        self.dyn = np.array([-1, 0], dtype=np.int64)
        self.Wj = lay.wrench_jacobian if n else np.zeros((0, lay.nv))
        if not n or _has_callbacks(dyn) or any(
            type(c) not in (Contact, SurfaceContact)
            or _has_callbacks(c)
            or _has_callbacks(c.existence)
            for c in contacts
        ):
            return
        model = self.robot.model
        for i, c in enumerate(contacts):
            frame = model.frames[c.fid]
            surface = isinstance(c, SurfaceContact)
            self.ct_tab[i] = [frame.parentJoint, c.existence_rows,
                              offset_in(c.existence.C, plan.M), 0, surface,
                              offset_in(c.C, plan.M) if surface else 0,
                              c.faces_local.shape[0] if surface else 0, c.wrench_slice().start]
            if surface:
                self.ct_faces[i, : c.faces_local.shape[0]] = c.faces_local
            par = self.ct_par[i]
            par[ck.CT_R: ck.CT_R + 9] = frame.placement.rotation.reshape(-1)
            par[ck.CT_P: ck.CT_P + 3] = frame.placement.translation
            offset = getattr(c, 'offset', None)
            if offset is not None:
                par[ck.CT_OFF: ck.CT_OFF + 3] = offset
            for j in model.supports[frame.parentJoint]:
                if j > 0:
                    jm = model.joints[j]
                    self.ct_sup[i, jm.idx_v: jm.idx_v + jm.nv] = True
        if dyn.rows():
            self.dyn[0] = offset_in(dyn.C, plan.M)
        inside = {id(c.existence) for c in contacts} | {id(dyn)}
        self.python = [o for o in self.python if id(o) not in inside]
        self.contact_objects = [o for o in self.python if id(o) in {id(c) for c in contacts}]
        self.python = [o for o in self.python if o not in self.contact_objects]
        for c in contacts:
            self.in_python.pop(c.existence.name, None)
            self.in_python[c.name] = (
                'its rows after a change of its state (its kinematics and the cone of a sole,'
                ' which turns with it, by kernel)'
            )
        self.in_python.pop(dyn.name, None)
        self.contacts, self.dynamics, self.owns_layout = contacts, dyn, True
        self._ct_seen = [None] * n  # (gain, normal) last written to ct_par
        lay.T, lay.t0 = lay.T_own, lay.t0_own

    def _contacts(self, t: float, dt: float, full: bool) -> None:
        """
        Run the contacts' own updates, mirror their existence conditions, then the kernel.

        Their updates only on a full pass (an object changed since the last one): what else
        changes from cycle to cycle in their rows is the kernel's (a sole's cone turns with it).
        """
        if full:
            self._contact_objects(t, dt)
        self._run_contacts(self.ws, dt)

    def _contact_objects(self, t: float, dt: float) -> None:
        for c in self.contact_objects:
            c.update(t, dt)
        tab, par, seen = self.ct_tab, self.ct_par, self._ct_seen
        for i, c in enumerate(self.contacts):
            ex = c.existence
            if ex.state is not c.state or ex.ramp_factor != c.ramp_factor:
                ex.state, ex.ramp_factor = c.state, c.ramp_factor  # it mirrors its contact
            tab[i, 3] = c.state not in _INACTIVE
            # gain and normal change only through their setters: written when they did
            normal = None if tab[i, 4] else c.normal  # a surface's: its frame's z axis
            if seen[i] is None or seen[i][0] != c.velocity_gain or seen[i][1] is not normal:
                par[i, ck.CT_GAIN] = c.velocity_gain
                if normal is not None:
                    par[i, ck.CT_N: ck.CT_N + 3] = normal
                seen[i] = (c.velocity_gain, normal)
        dyn = self.dynamics
        if dyn.state is not _ACTIVATED and dyn.state not in _INACTIVE:
            dyn.step_ramp(t)
        self.dyn[1] = dyn.state not in _INACTIVE

    def _bind_wrenches(self, lay) -> None:
        """
        Make the contacts' last wrenches rows of one array, which the finish kernel writes.

        (``ContactBase.record_solution``, for every contact of the layout.)
        """
        contacts = list(lay.contacts)
        self.ct_ws = np.array([c.wrench_slice().start for c in contacts] or [0], dtype=np.int64)
        self.ct_last = np.zeros((max(1, len(contacts)), 6))
        for i, c in enumerate(contacts):
            self.ct_last[i] = c.last_wrench
            c.last_wrench = self.ct_last[i]
        self.n_wrenches = len(contacts)
