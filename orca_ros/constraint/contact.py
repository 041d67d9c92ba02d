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
Unilateral point contact with a linearised Coulomb friction cone.

A contact owns one external wrench w = [f, m] (world axes, applied by the environment on the robot
at the contact point) among the QP variables; the dynamics see it through J_c^T w. For a point
contact m = 0 (fixed by the variable bounds) and f must lie in the friction cone of normal n and
coefficient mu, approximated from inside by a pyramid of ``number_of_faces`` faces:

    d_k . f <= mu_eff (n . f),   d_k = cos(2 pi k / N) t1 + sin(2 pi k / N) t2,
    mu_eff = (mu - margin) cos(pi / N)
    min_normal_force <= n . f <= f_max(t)

(``mu_eff`` puts the pyramid's edges inside the cone shrunk by ``margin``: every solution is inside
the true cone). The *existence condition* (:class:`ContactExistenceCondition`, added with the
contact) keeps the contact point from accelerating: J_p nu_dot + J_dot_p nu = 0 (3 rows).

Activation ramps f_max smoothly: switching a contact on raises the bound from 0 to
``maximum_normal_force``; switching it off lowers it from the normal force the contact carried when
the deactivation started to 0, so a foot is unloaded progressively before it leaves the ground. A
deactivated contact's wrench is held at zero.
"""

from __future__ import annotations

import numpy as np

from .generic_constraint import GenericConstraint
from ..common.task_base import ActivationState


def _skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def point_terms(robot, frame_id: int, offset):
    """
    Return the kinematics of a point rigidly attached to a frame.

    (position, J 6 x nv, velocity 6, bias acceleration 6) of a point rigidly attached to a frame
    (offset in the frame's axes), world axes; linear rows are the point's, angular rows the
    frame's.
    """
    T, J, vel, acc = robot.world_frame_terms(frame_id)
    if offset is None:
        return T[:3, 3], J, vel, acc
    r = T[:3, :3] @ offset
    Jp = J.copy()
    Jp[:3] -= _skew(r) @ J[3:]
    w = vel[3:]
    v = vel.copy()
    v[:3] += np.cross(w, r)
    a = acc.copy()
    a[:3] += np.cross(acc[3:], r) + np.cross(w, np.cross(w, r))
    return T[:3, 3] + r, Jp, v, a


# 1/s. 0: as a default, 200 /s made the lockstep quadruped's first contact cycle infeasible (feet
# landing: the hard equality asked for more friction than the cones allow)
DEFAULT_VELOCITY_GAIN = 0.0


class ContactBase(GenericConstraint):
    """Something that owns an external wrench variable (point, surface or bilateral contact)."""

    kind = 'inequality'
    is_contact = True

    def __init__(self, name: str):
        super().__init__(name)
        self.wrench_index = None
        self.frame = None
        self.fid = None
        self.wrench_lower = np.zeros(6)
        self.wrench_upper = np.zeros(6)
        self.existence = None
        self.last_wrench = np.zeros(6)
        # 1/s: existence condition J nu_dot + J_dot nu = -gain J nu (capped at 0.5 / dt)
        self.velocity_gain = DEFAULT_VELOCITY_GAIN

    def set_velocity_feedback_gain(self, gain: float) -> None:
        """
        Make a contact that moves come to rest: J nu_dot + J_dot nu = -gain * J nu.

        0 only stops it from accelerating, so a contact set sliding (a push, an impact) keeps
        sliding. The slip then decays with time constant 1 / gain [s]; keep 1 / gain several
        control periods long.
        """
        gain = float(gain)
        if not (np.isfinite(gain) and gain >= 0.0):
            raise ValueError(f"contact '{self.name}': velocity gain must be >= 0, got {gain}")
        self.velocity_gain = gain

    def feedback_velocity(self, v: np.ndarray) -> None:
        """Adjust the velocity the existence condition feeds back, in place (all of it here)."""

    def set_contact_frame(self, frame: str) -> None:
        if self.robot is not None:
            self.fid = self.robot.get_frame_id(frame)
        self.frame = frame

    def set_robot_model(self, robot) -> None:
        super().set_robot_model(robot)
        if self.frame is not None:
            self.fid = robot.get_frame_id(self.frame)

    def parts(self):
        """Constraints the controller adds together with this one."""
        return [self.existence] if self.existence is not None else []

    def wrench_slice(self) -> slice:
        return self.layout.wrench_slice(self.wrench_index)

    def get_wrench(self, x: np.ndarray) -> np.ndarray:
        """Return this contact's wrench [force, torque] (world axes) in a reduced solution x."""
        return x[self.wrench_slice()].copy()

    def record_solution(self, x: np.ndarray) -> None:
        self.last_wrench[:] = x[self.wrench_slice()]

    def fill_wrench_jacobian(self, out: np.ndarray) -> None:
        raise NotImplementedError

    #: points that bound the support polygon (see support_points)
    support_point_count = 1

    def support_points(self) -> np.ndarray:
        """Return the contact's points in the world (support_point_count x 3)."""
        T = self.robot.world_frame_placement(self.fid)
        offset = getattr(self, 'offset', None)
        point = T[:3, 3] if offset is None else T[:3, 3] + T[:3, :3] @ offset
        return point[None, :]


class NormalForceRamp:
    """
    The normal force bound of a unilateral contact follows its activation ramp.

    Switched on, from 0 up to ``maximum_normal_force``; switched off, from the normal force it
    carried then down to 0 (the load moves to the other contacts progressively before the contact
    is released). What else the unilateral contacts (point and surface) share is here too: their
    normal, and the part of their velocity the existence condition feeds back.
    """

    maximum_normal_force = 1000.0
    _release_force = None  # normal force when the deactivation started

    def set_maximum_normal_force(self, f: float) -> None:
        if not (np.isfinite(f) and f > 0):
            raise ValueError(f"contact '{self.name}': maximum normal force must be > 0, got {f}")
        self.maximum_normal_force = float(f)

    def contact_normal_world(self) -> np.ndarray:
        return self.normal

    def feedback_velocity(self, v: np.ndarray) -> None:
        """
        Drop, in place, the part of the contact's velocity v that goes into the surface.

        The surface stops that part itself. Fed back, it made a landing foot ask for a spike of
        normal force (an acceleration out of the surface of the gain times its landing speed).
        Sliding, and lifting off, stay in.
        """
        n = self.contact_normal_world()
        vn = float(n @ v[:3])
        if vn < 0.0:
            v[:3] -= vn * n

    def deactivate(self) -> bool:
        self._release_force = max(float(self.contact_normal_world() @ self.last_wrench[:3]), 0.0)
        return super().deactivate()

    def normal_force_bound(self) -> float:
        """Upper bound on the normal force this cycle (follows the activation ramp)."""
        if not self.is_computing():
            return 0.0
        rho = self.get_ramp_value()
        if self._release_force is not None and self.state is ActivationState.DEACTIVATING:
            return rho * self._release_force
        return rho * self.maximum_normal_force

    def settle_ramp(self) -> None:
        """Forget the release force once the contact is fully on again."""
        if self.state is ActivationState.ACTIVATED:
            self._release_force = None


class Contact(NormalForceRamp, ContactBase):
    def __init__(self, name: str, frame: str | None = None, offset=None):
        super().__init__(name)
        self.mu = 0.6
        self.margin = 0.0
        self.n_faces = 4
        self.normal = np.array([0.0, 0.0, 1.0])
        self.minimum_normal_force = 0.0
        self.offset = None if offset is None else np.asarray(offset, dtype=float).reshape(3)
        self._faces = None
        self._written_C = self._written_faces = (
            None  # what the constant rows were last written for
        )
        self.existence = ContactExistenceCondition(f'{name}_existence', self)
        if frame is not None:
            self.set_contact_frame(frame)
        self._make_faces()

    def activate(self) -> bool:
        self._written_C = None
        return super().activate()

    # -------------------------------------------------------------- configuration
    def set_friction_coefficient(self, mu: float) -> None:
        if not (np.isfinite(mu) and mu > 0):
            raise ValueError(f"contact '{self.name}': friction coefficient must be > 0, got {mu}")
        self.mu = float(mu)
        self._make_faces()

    def set_margin(self, margin: float) -> None:
        if not (0.0 <= margin < self.mu):
            raise ValueError(
                f"contact '{self.name}': margin must be in [0, mu = {self.mu}), got {margin}"
            )
        self.margin = float(margin)
        self._make_faces()

    def set_number_of_faces(self, n: int) -> None:
        if int(n) < 3:
            raise ValueError(
                f"contact '{self.name}': a friction pyramid needs at least 3 faces, got {n}"
            )
        self.n_faces = int(n)
        self._make_faces()
        if self.layout is not None:
            raise RuntimeError('set the number of faces before adding the contact to a controller')

    def set_contact_normal(self, normal) -> None:
        """
        Set the normal of the contact surface (pointing from the environment to the robot).

        World axes.
        """
        n = np.asarray(normal, dtype=float).reshape(3)
        if not np.all(np.isfinite(n)) or np.linalg.norm(n) < 1e-9:
            raise ValueError(f"contact '{self.name}': invalid normal {normal}")
        self.normal = n / np.linalg.norm(n)
        self._make_faces()

    def set_cone_orientation(self, world_R_cone) -> None:
        """Orientation of the cone frame; its z axis is the contact normal."""
        R = np.asarray(world_R_cone, dtype=float).reshape(3, 3)
        self.set_contact_normal(R[:, 2])

    def set_minimum_normal_force(self, f: float) -> None:
        self.minimum_normal_force = max(0.0, float(f))

    def _make_faces(self) -> None:
        n = self.normal
        t1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(n, t1)
        mu_eff = (self.mu - self.margin) * np.cos(np.pi / self.n_faces)
        ang = 2.0 * np.pi * np.arange(self.n_faces) / self.n_faces
        d = np.cos(ang)[:, None] * t1 + np.sin(ang)[:, None] * t2
        self._faces = d - mu_eff * n  # rows: (d_k - mu_eff n) . f <= 0
        self.mu_effective = mu_eff

    @property
    def faces(self) -> np.ndarray:
        """Return the friction pyramid's faces, one row a_k per face: a_k . f <= 0 inside."""
        return self._faces.copy()

    # -------------------------------------------------------------- rows
    def rows(self) -> int:
        return self.n_faces + 1

    def fill_wrench_jacobian(self, out: np.ndarray) -> None:
        _, J, _, _ = point_terms(self.robot, self.fid, self.offset)
        out[:] = J

    def point_terms(self):
        return point_terms(self.robot, self.fid, self.offset)

    existence_rows = 3

    def existence_terms(self):
        _, J, _, bias = self.point_terms()
        return J[:3], bias[:3]

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        nf = self.n_faces
        # the cone rows and the wrench bounds change only with the settings (new faces), the rows'
        # place in the plan (new views) and a switch-on (the plan relaxed the rows while off):
        # rewritten then; every cycle only the normal force bound follows the ramp
        if self._written_C is not self.C or self._written_faces is not self._faces:
            computing = self.is_computing()
            ws = self.wrench_slice()
            f = slice(ws.start, ws.start + 3)
            self.C[:nf, f] = self._faces
            self.lb[:nf] = -np.inf
            self.ub[:nf] = 0.0
            self.C[nf, f] = self.normal
            # force free (the rows above bound it), torque of a point contact zero; all zero when
            # switched off
            free = np.inf if computing else 0.0
            self.wrench_lower[:3], self.wrench_upper[:3] = -free, free
            self.wrench_lower[3:], self.wrench_upper[3:] = 0.0, 0.0
            self._written_C, self._written_faces = self.C, self._faces
        bound = self.normal_force_bound()
        self.lb[nf] = min(self.minimum_normal_force * self.ramp_factor, bound)
        self.ub[nf] = bound
        self.settle_ramp()


class ContactExistenceCondition(GenericConstraint):
    """
    While its contact is on, the contact does not move.

    J nu_dot + J_dot nu = -gain J nu on the rows the contact gives (:meth:`existence_terms`: the
    point's linear rows, or the 6 relative rows of a bilateral contact; ``gain``: the contact's
    :meth:`ContactBase.set_velocity_feedback_gain`, 0 by default).
    """

    kind = 'equality'

    def __init__(self, name: str, contact):
        super().__init__(name)
        self.contact = contact

    def is_computing(self) -> bool:
        return self.contact.is_computing()

    def rows(self) -> int:
        return self.contact.existence_rows

    def update(self, current_time: float, dt: float) -> None:
        self.state, self.ramp_factor = (
            self.contact.state,
            self.contact.get_ramp_value(),
        )  # mirrors it
        if not self.contact.is_computing():
            return
        J, bias = self.contact.existence_terms()
        self.C[:, self.layout.acc] = J
        np.negative(bias, out=self.lb)
        # at most half the slip removed per control period: gain * dt >= 1 would overshoot
        gain = min(self.contact.velocity_gain, 0.5 / dt) if dt > 0.0 else 0.0
        if gain > 0.0:
            v = J @ self.contact.robot.get_generalized_velocity()
            self.contact.feedback_velocity(v)
            self.lb -= gain * v
        self.ub[:] = self.lb


def surface_contact(name: str, frame: str, points, **settings) -> list[Contact]:
    """
    Make a contact of unilateral point contacts at ``points`` (offsets in the frame's axes).

    For a flat contact (a foot sole, a hand on a table) use
    :class:`~orca_ros.constraint.surface_wrench_contact.SurfaceContact` instead: the same physics
    (the centre of pressure inside the sole, torsional friction) as one 6-D wrench, where these
    points cost 6 variables and 3 rank-deficient existence rows each (several times slower per
    step for a biped's two soles of four corners). This form remains for
    points that are not on the frame's xy plane, or when each point's force is wanted.

    ``settings``: friction_coefficient, margin, number_of_faces, contact_normal,
    maximum_normal_force, ramp_duration. Add each returned contact to the controller.
    """
    setters = {
        'number_of_faces': 'set_number_of_faces',
        'friction_coefficient': 'set_friction_coefficient',
        'margin': 'set_margin',
        'contact_normal': 'set_contact_normal',
        'maximum_normal_force': 'set_maximum_normal_force',
        'ramp_duration': 'set_ramp_duration',
    }
    unknown = set(settings) - set(setters)
    if unknown:
        raise ValueError(f"surface_contact '{name}': unknown settings {sorted(unknown)}")
    out = []
    for i, p in enumerate(points):
        c = Contact(f'{name}_{i}', frame, offset=p)
        for (
            key
        ) in setters:  # in this order: the faces before the coefficient and margin that use them
            if key in settings:
                getattr(c, setters[key])(settings[key])
        out.append(c)
    return out
