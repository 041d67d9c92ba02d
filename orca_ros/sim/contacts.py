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
Contact readout of a simulated robot: where it touches, and with what force.

PyBullet reports, per contact point, the normal on the *other* body pointing towards the robot, the
normal force along it and two friction forces along orthogonal lateral directions. A
:class:`ContactPoint` gives them in world coordinates with link names, and the total force the
world exerts on the robot's link.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
