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
Named static obstacles in the PyBullet world: spheres, boxes, cylinders placed, moved, removed.

An obstacle is a body without mass of its shape (``size``: a sphere's radius, a box's edge
lengths, a cylinder's radius and length, as :func:`orca_ros.ros.obstacle_markers.marker_obstacle`
gives them), so that a collision in the simulation is a real one. :meth:`depth_into` tells how far
an obstacle goes into a robot's moving links: PyBullet pushes links out of an obstacle at once, as
no real obstacle can, so a caller refuses one that goes in deeper than it allows.
"""

from __future__ import annotations

import numpy as np
import pybullet

from ..math.rotations import quaternion_xyzw

COLOR = [0.8, 0.3, 0.2, 0.6]


class PyBulletObstacles:
    def __init__(self, client):
        self._client = client
        self._bodies: dict = {}  # name -> PyBullet body

    def names(self) -> list[str]:
        return sorted(self._bodies)

    def add(self, name: str, shape: str, size, pose) -> None:
        """Add obstacle ``name`` (replacing one of that name) at ``pose`` (4x4, world)."""
        if name in self._bodies:
            self.remove(name)
        c = self._client
        if shape == 'sphere':
            kw = {'shapeType': pybullet.GEOM_SPHERE, 'radius': size[0]}
        elif shape == 'box':
            kw = {'shapeType': pybullet.GEOM_BOX, 'halfExtents': (np.asarray(size) / 2).tolist()}
        elif shape == 'cylinder':
            kw = {'shapeType': pybullet.GEOM_CYLINDER, 'radius': size[0]}
        else:
            raise ValueError(f"shape '{shape}' is not sphere, box or cylinder")
        col = c.createCollisionShape(**kw, **({'height': size[1]} if shape == 'cylinder' else {}))
        vis = c.createVisualShape(**kw, **({'length': size[1]} if shape == 'cylinder' else {}),
                                  rgbaColor=COLOR)
        position, orientation = _placement(pose)
        self._bodies[name] = c.createMultiBody(
            baseMass=0.0, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
            basePosition=position, baseOrientation=orientation)

    def move(self, name: str, pose) -> None:
        """Place obstacle ``name`` at ``pose`` (4x4, world)."""
        self._client.resetBasePositionAndOrientation(self._bodies[name], *_placement(pose))

    def pose(self, name: str) -> np.ndarray:
        """Return the 4x4 pose of obstacle ``name`` in the world."""
        position, orientation = self._client.getBasePositionAndOrientation(self._bodies[name])
        T = np.eye(4)
        T[:3, :3] = np.array(pybullet.getMatrixFromQuaternion(orientation)).reshape(3, 3)
        T[:3, 3] = position
        return T

    def remove(self, name: str) -> None:
        self._client.removeBody(self._bodies.pop(name))

    def depth_into(self, name: str, model) -> tuple[float, str]:
        """
        Return how deep obstacle ``name`` goes into ``model``'s moving links [m], and the link.

        (0, '') when it touches none. A fixed base's root link does not move: not counted.
        """
        c, deepest = self._client, None
        for p in c.getClosestPoints(bodyA=self._bodies[name], bodyB=model.body, distance=0.0):
            if (p[4] >= 0 or not model.fixed_base) and (deepest is None or p[8] < deepest[8]):
                deepest = p
        if deepest is None or deepest[8] >= 0.0:
            return 0.0, ''
        link = c.getJointInfo(model.body, deepest[4])[12].decode() if deepest[4] >= 0 else 'base'
        return -float(deepest[8]), link


def _placement(pose):
    pose = np.asarray(pose, dtype=float)
    return pose[:3, 3].tolist(), quaternion_xyzw(pose[:3, :3]).tolist()
