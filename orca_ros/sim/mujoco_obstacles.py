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
Named static obstacles in the MuJoCo world, with the PyBullet world's contract.

As :class:`~.pybullet_obstacles.PyBulletObstacles`.

Each obstacle is a mocap body (placed, never pushed) carrying one geom of its shape. Adding or
removing one recompiles the world (the robots keep their state); moving one writes its mocap pose
only. Obstacles touch the robots, not the ground nor each other (``OBSTACLE_BIT``).
"""

from __future__ import annotations

import mujoco
import numpy as np

from .mujoco_robot_spec import ALL_BITS, OBSTACLE_BIT
from ..math.rotations import quaternion_xyzw

COLOR = [0.8, 0.3, 0.2, 0.6]
_TYPES = {'sphere': mujoco.mjtGeom.mjGEOM_SPHERE, 'box': mujoco.mjtGeom.mjGEOM_BOX,
          'cylinder': mujoco.mjtGeom.mjGEOM_CYLINDER}


def _wxyz(rotation) -> list:
    x, y, z, w = quaternion_xyzw(rotation)
    return [float(w), float(x), float(y), float(z)]


class MujocoObstacles:
    PREFIX = 'obstacle:'

    def __init__(self, server):
        self._server = server
        self._names: list[str] = []

    def names(self) -> list[str]:
        return sorted(self._names)

    def add(self, name: str, shape: str, size, pose) -> None:
        """Add obstacle ``name`` (replacing one of that name) at ``pose`` (4x4, world)."""
        if shape not in _TYPES:
            raise ValueError(f"shape '{shape}' is not sphere, box or cylinder")
        if name in self._names:
            self.remove(name)
        pose = np.asarray(pose, dtype=float)
        if shape == 'sphere':
            half = [size[0], 0.0, 0.0]
        elif shape == 'box':
            half = [s / 2.0 for s in size]
        else:
            half = [size[0], size[1] / 2.0, 0.0]
        body = self._server.spec.worldbody.add_body(
            name=self.PREFIX + name, mocap=True, pos=pose[:3, 3].tolist(),
            quat=_wxyz(pose[:3, :3]))
        body.add_geom(type=_TYPES[shape], size=half, rgba=COLOR, contype=OBSTACLE_BIT,
                      conaffinity=ALL_BITS & ~OBSTACLE_BIT & ~1)
        self._names.append(name)
        self._server.recompile()

    def _mocap(self, name: str) -> int:
        if name not in self._names:
            raise KeyError(name)
        m = self._server.model
        return int(m.body_mocapid[m.body(self.PREFIX + name).id])

    def move(self, name: str, pose) -> None:
        """Place obstacle ``name`` at ``pose`` (4x4, world)."""
        k, d = self._mocap(name), self._server.data
        pose = np.asarray(pose, dtype=float)
        d.mocap_pos[k] = pose[:3, 3]
        d.mocap_quat[k] = _wxyz(pose[:3, :3])
        mujoco.mj_kinematics(self._server.model, d)

    def pose(self, name: str) -> np.ndarray:
        """Return the 4x4 pose of obstacle ``name`` in the world."""
        k, d = self._mocap(name), self._server.data
        T, mat = np.eye(4), np.zeros(9)
        mujoco.mju_quat2Mat(mat, d.mocap_quat[k])
        T[:3, :3] = mat.reshape(3, 3)
        T[:3, 3] = d.mocap_pos[k]
        return T

    def remove(self, name: str) -> None:
        spec = self._server.spec
        spec.delete(spec.body(self.PREFIX + name))
        self._names.remove(name)
        self._server.recompile()

    def depth_into(self, name: str, model) -> tuple[float, str]:
        """
        Return how deep obstacle ``name`` goes into ``model``'s moving links [m], and the link.

        (0, '') when it touches none. Bodies welded to the world (a fixed base) are not counted.
        """
        m, d = self._server.model, self._server.data
        mine = m.body_geomadr[m.body(self.PREFIX + name).id]
        fromto, deepest = np.zeros(6), (0.0, '')
        for link, geom in model.collision_geoms():
            if m.body_weldid[m.geom_bodyid[geom]] == 0:
                continue
            gap = mujoco.mj_geomDistance(m, d, mine, geom, 0.0, fromto)
            if gap < -deepest[0]:
                deepest = (-float(gap), link)
        return deepest
