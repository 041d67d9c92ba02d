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
What the contacts hold at the controller's last solution, for a view (no ROS).

The centre of mass of the model's current state, the support polygon (the convex hull, in the
horizontal plane, of the points of the contacts that compute and may carry load, as the balance
constraint takes it; placed at their lowest height) and per contact its point and the force the
last solution gave it (world axes).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .balance_constraint import convex_hull_2d


@dataclass
class ContactForce:
    name: str
    point: np.ndarray  # world [m]
    force: np.ndarray  # world axes [N]


@dataclass
class SupportSummary:
    com: np.ndarray  # world [m]
    polygon: np.ndarray  # (k, 3), counter-clockwise seen from above; k < 3: no polygon
    contacts: list = field(default_factory=list)  # ContactForce of the computing contacts


def _may_carry_load(contact) -> bool:
    bound = getattr(contact, 'normal_force_bound', None)  # bilateral contacts have none
    return bound is None or bound() > 0.0


def support_summary(robot, contacts) -> SupportSummary:
    """Summarize the contacts (``controller.layout.contacts``) at the model's current state."""
    forces, support = [], []
    for c in contacts:
        if not c.is_computing():
            continue
        points = c.support_points()
        forces.append(ContactForce(c.name, points.mean(axis=0), np.array(c.last_wrench[:3])))
        if _may_carry_load(c):
            support.append(points)
    polygon = np.zeros((0, 3))
    if support:
        pts = np.concatenate(support)
        hull = convex_hull_2d(pts[:, :2])
        polygon = np.column_stack((hull, np.full(len(hull), pts[:, 2].min())))
    return SupportSummary(np.array(robot.get_center_of_mass(), dtype=float), polygon, forces)
