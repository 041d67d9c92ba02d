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
What the quadruped example needs to know about a quadruped, read from its model.

The shipped 12-joint quadruped (``urdf/quadruped.urdf``) by default. Another one from its URDF
(and an SRDF with its standing pose):

- the trunk: the URDF's root link (the free-flyer's child);
- the feet: the tips of the four chains (the last link on each joint without a child), named
  FL / FR / HL / HR by where they stand around the trunk (front: +x, left: +y);
- the standing configuration: the SRDF's ``standing`` pose (the neutral one without an SRDF),
  lowered or raised so that the lowest foot touches the ground (z = 0);
- the foot radius: the sphere of the foot link's collision in the URDF (``foot_radius`` when the
  foot is a mesh).
"""

from __future__ import annotations

from dataclasses import dataclass
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from .. import RobotModel, share_path

LEGS = ('FL', 'FR', 'HL', 'HR')
STAND_Q = np.tile([0.0, 0.7, -1.4], 4)  # feet under the hips
STAND_HEIGHT = (
    0.2 * 2 * np.cos(0.7) + 0.02
)  # trunk origin above the ground: two 0.2 m segments + foot radius
FOOT_RADIUS = 0.02


@dataclass(frozen=True)
class Quadruped:
    """A quadruped standing: its URDF, trunk and feet frames, configuration, foot radius."""

    urdf: str
    trunk: str
    feet: dict  # leg (FL, FR, HL, HR) -> foot frame
    q: np.ndarray  # standing configuration: base position, quaternion (x, y, z, w), joints
    foot_radius: float

    @property
    def joints(self) -> np.ndarray:
        """Joint positions standing (Pinocchio's order)."""
        return self.q[7:]

    @property
    def home(self) -> np.ndarray:
        """Position of the trunk standing (world)."""
        return self.q[:3]


def shipped() -> Quadruped:
    """Return the shipped quadruped (urdf/quadruped.urdf) standing with its feet under the hips."""
    q = np.concatenate(([0.0, 0.0, STAND_HEIGHT, 0.0, 0.0, 0.0, 1.0], STAND_Q))
    return Quadruped(
        share_path('urdf', 'quadruped.urdf'),
        'trunk',
        {leg: f'{leg}_foot' for leg in LEGS},
        q,
        FOOT_RADIUS,
    )


def _sphere_radius(urdf: str, link: str) -> float | None:
    root = ET.parse(urdf).getroot()
    for el in root.findall('link'):
        if el.get('name') == link:
            sphere = el.find('collision/geometry/sphere')
            return None if sphere is None else float(sphere.get('radius'))
    return None


def from_urdf(
    urdf: str, srdf: str | None = None, pose: str = 'standing', foot_radius: float | None = None
) -> Quadruped:
    """Describe the quadruped of ``urdf`` (see the module's text)."""
    robot = RobotModel()
    robot.load_model_from_file(urdf, floating_base=True)
    model = robot.model
    parents = set(model.parents[1:])
    leaves = [j for j in range(2, model.njoints) if j not in parents]
    if len(leaves) != 4:
        raise ValueError(f"'{urdf}': {len(leaves)} kinematic chains end in a foot, not 4")
    tips = [
        [f.name for f in model.frames if f.parentJoint == j and f.type == pin.FrameType.BODY][-1]
        for j in leaves
    ]
    if srdf is not None:
        pin.loadReferenceConfigurations(model, srdf, False)
        q = np.array(model.referenceConfigurations[pose])
    else:
        q = pin.neutral(model)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    at = np.array([data.oMf[model.getFrameId(f)].translation for f in tips])
    rel = at[:, :2] - at[:, :2].mean(axis=0)
    feet = {('F' if x > 0 else 'H') + ('L' if y > 0 else 'R'): f for (x, y), f in zip(rel, tips)}
    if sorted(feet) != sorted(LEGS):
        raise ValueError(f"'{urdf}': the feet {tips} do not stand at four corners")
    if foot_radius is None:
        foot_radius = _sphere_radius(urdf, tips[0]) or 0.0
    q[2] += foot_radius - at[:, 2].min()
    return Quadruped(urdf, robot.get_base_frame(), {leg: feet[leg] for leg in LEGS}, q,
                     foot_radius)
