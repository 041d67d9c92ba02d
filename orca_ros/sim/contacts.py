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
Contacts of a simulated robot: where it touches and with what force, its friction, pushes.

PyBullet reports, per contact point, the normal on the *other* body pointing towards the robot, the
normal force along it and two friction forces along orthogonal lateral directions. A
:class:`ContactPoint` gives them in world coordinates with link names, and the total force the
world exerts on the robot's link.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pybullet


@dataclass
class ContactPoint:
    link: str  # the robot's link in contact
    other_body: int  # PyBullet body id of what it touches (the ground plane, another robot...)
    other_link: int  # link index on that body (-1: its base)
    position: np.ndarray  # contact point on the robot, world frame [m]
    position_on_other: np.ndarray  # contact point on the other body, world frame [m]
    normal: np.ndarray  # unit normal, world frame, from the other body towards the robot
    distance: float  # signed separation [m] (negative: penetration)
    normal_force: float  # along ``normal`` [N], >= 0
    friction_force: np.ndarray  # tangential force on the robot, world frame [N]

    @property
    def force(self) -> np.ndarray:
        """Total force the other body exerts on the robot at this point (world frame) [N]."""
        return self.normal_force * self.normal + self.friction_force


def read_contacts(client, body: int, link_names: dict) -> list[ContactPoint]:
    """Contact points of ``body`` (``link_names``: PyBullet link index -> name, -1 the base)."""
    out = []
    for c in client.getContactPoints(bodyA=body):
        n = np.array(c[7])
        # PyBullet gives the lateral forces acting on the other body: the robot feels the opposite
        friction = -(c[10] * np.array(c[11]) + c[12] * np.array(c[13]))
        out.append(
            ContactPoint(
                link=link_names.get(c[3], str(c[3])),
                other_body=int(c[2]),
                other_link=int(c[4]),
                position=np.array(c[5]),
                position_on_other=np.array(c[6]),
                normal=n,
                distance=float(c[8]),
                normal_force=float(c[9]),
                friction_force=friction,
            )
        )
    return out


def friction_values(lateral, spinning=None, rolling=None) -> dict:
    """Return the ``changeDynamics`` keywords of the friction coefficients given (>= 0)."""
    values = {'lateralFriction': float(lateral)}
    if spinning is not None:
        values['spinningFriction'] = float(spinning)
    if rolling is not None:
        values['rollingFriction'] = float(rolling)
    if not all(np.isfinite(v) and v >= 0 for v in values.values()):
        raise ValueError(f'friction coefficients must be finite and >= 0, got {values}')
    return values


class ContactsMixin:
    """Friction, contacts and pushes of a :class:`~orca_ros.sim.SimModel` (its body and links)."""

    def set_friction(self, lateral: float, spinning=None, rolling=None, links=None) -> None:
        """
        Coulomb friction coefficients of the named links (default: every link and the base).

        PyBullet combines the coefficients of two touching bodies by multiplying them; the ground
        plane's are 1 unless :meth:`SimServer.set_ground_friction` changes them.
        """
        values = friction_values(lateral, spinning, rolling)
        ids = (
            range(-1, self.client.getNumJoints(self.body))
            if links is None
            else [self._link(n) for n in links]
        )
        for link in ids:
            self.client.changeDynamics(self.body, link, **values)

    def get_friction(self, link: str) -> dict:
        """Lateral, spinning and rolling friction coefficients of a link."""
        info = self.client.getDynamicsInfo(self.body, self._link(link))
        return {'lateral': info[1], 'rolling': info[6], 'spinning': info[7]}

    def get_contacts(self, links=None) -> list[ContactPoint]:
        """Contact points after the last step (of the named links only, when given)."""
        names = {i: n for n, i in self._link_names().items()}
        points = read_contacts(self.client, self.body, names)
        if links is None:
            return points
        for n in links:
            self._link(n)  # unknown names are refused
        wanted = set(links)
        return [c for c in points if c.link in wanted]

    def apply_external_force(self, link: str, force, position=None) -> None:
        """
        Push ``link`` with a world-frame force [N] during the next step (a push, a tug).

        Applied at ``position`` (world frame) or at the link frame's origin. PyBullet forgets
        external forces after each step: call it before every step of the push.
        """
        f = np.asarray(force, dtype=float).reshape(3)
        if not np.isfinite(f).all():
            raise ValueError(f'external force must be finite, got {force!r}')
        index = self._link(link)
        if position is None:
            position = (
                self.get_world_to_base_transform()[:3, 3]
                if index == -1
                else self.get_link_position(link)
            )
        self.client.applyExternalForce(
            self.body, index, f.tolist(), list(map(float, position)), pybullet.WORLD_FRAME
        )

    def get_contact_force(self, link: str) -> np.ndarray:
        """Total force the world exerts on ``link`` through its contacts (world frame) [N]."""
        f = np.zeros(3)
        for c in self.get_contacts([link]):
            f += c.force
        return f

    def _link_names(self) -> dict:
        if not hasattr(self, '_link_index'):
            try:
                self._link('')
            except ValueError:
                pass
        return self._link_index
