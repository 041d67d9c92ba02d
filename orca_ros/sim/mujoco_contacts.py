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
A MuJoCo robot's contacts as :class:`~orca_ros.sim.contacts.ContactPoint`, and friction.

MuJoCo reports each active contact once, between two geoms, in a frame whose first axis is the
normal from the first geom to the second; ``mj_contactForce`` gives the force the first geom
exerts on the second in that frame (normal, then two tangents). A robot's contact point is
turned to the robot's side: the normal points from the other body towards the robot and the
force is the one the robot feels, as PyBullet's contacts are read. ``pos`` is midway between the
two surfaces; each side's point is half the signed distance along the normal from it.

Friction: MuJoCo combines two geoms' coefficients by their maximum (PyBullet multiplies them);
torsional (spinning) friction needs ``condim`` 4 and rolling friction ``condim`` 6.
"""

from __future__ import annotations

import mujoco
import numpy as np

from .contacts import ContactPoint


def robot_contacts(model, data, bodies: dict, wanted=None) -> list[ContactPoint]:
    """
    Return the contacts of the robot whose bodies are ``bodies`` (body id -> link name).

    ``wanted``: body ids to keep (None: all the robot's). ``other_body``: the root body id of
    what it touches (0: the world, the ground plane); ``other_link``: that body's id.
    """
    out, f6 = [], np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        if c.efc_address < 0:  # found by the collision pass, excluded from the solver
            continue
        b0, b1 = int(model.geom_bodyid[c.geom[0]]), int(model.geom_bodyid[c.geom[1]])
        if b1 in bodies:
            mine, other, sign = b1, b0, 1.0
        elif b0 in bodies:
            mine, other, sign = b0, b1, -1.0
        else:
            continue
        if wanted is not None and mine not in wanted:
            continue
        mujoco.mj_contactForce(model, data, i, f6)
        frame = c.frame.reshape(3, 3)
        normal = sign * frame[0]
        out.append(ContactPoint(
            link=bodies[mine],
            other_body=int(model.body_rootid[other]),
            other_link=other,
            position=c.pos - 0.5 * c.dist * normal,
            position_on_other=c.pos + 0.5 * c.dist * normal,
            normal=normal,
            distance=float(c.dist),
            normal_force=float(f6[0]),
            friction_force=sign * (f6[1] * frame[1] + f6[2] * frame[2]),
        ))
    return out


def set_geom_friction(model, geoms, values: dict) -> None:
    """Write ``values`` (:func:`~orca_ros.sim.contacts.friction_values`' keys) into ``geoms``."""
    for g in geoms:
        model.geom_friction[g, 0] = values['lateralFriction']
        if 'spinningFriction' in values:
            model.geom_friction[g, 1] = values['spinningFriction']
            model.geom_condim[g] = max(int(model.geom_condim[g]), 4)
        if 'rollingFriction' in values:
            model.geom_friction[g, 2] = values['rollingFriction']
            model.geom_condim[g] = 6
