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
A robot's visual geometry from its URDF text, placed by a joint state (Pinocchio).

Each ``<visual>`` becomes one triangle mesh (primitives tessellated by :mod:`.shapes`, mesh files
read by Pinocchio's loader, ``package://`` resolved as the simulator does) with its colour; for
a joint state (positions by joint name, and the floating base's pose from odometry) the scene
gives every mesh's pose in the world, and the pose of any frame of the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from . import shapes
from ..robot.mjcf import build_mjcf_model, is_mjcf
from ..robot.urdf_text import resolve_package_uris


@dataclass
class Visual:
    name: str
    vertices: np.ndarray  # (n, 3), in the visual's own frame
    faces: np.ndarray  # (m, 3)
    rgba: tuple  # 0..1


def _mesh_of(geometry) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of a coal geometry (a primitive, or a mesh Pinocchio loaded)."""
    import coal  # noqa: PLC0415 - Pinocchio's collision library, loaded with it

    if isinstance(geometry, coal.Box):
        return shapes.box(2.0 * np.asarray(geometry.halfSide))
    if isinstance(geometry, coal.Cylinder):
        return shapes.cylinder(geometry.radius, 2.0 * geometry.halfLength)
    if isinstance(geometry, coal.Capsule):
        return shapes.sphere(geometry.radius, stretch=2.0 * geometry.halfLength)
    if isinstance(geometry, coal.Sphere):
        return shapes.sphere(geometry.radius)
    if hasattr(geometry, 'tri_indices') and geometry.num_tris > 0:
        verts = np.asarray(geometry.vertices(), dtype=float).reshape(-1, 3)
        faces = np.empty((geometry.num_tris, 3), dtype=np.int64)
        for k in range(geometry.num_tris):
            t = geometry.tri_indices(k)
            faces[k] = (t[0], t[1], t[2])
        return verts, faces
    raise ValueError(f'no mesh for a visual of type {type(geometry).__name__}')


def _models(text: str, path: str, floating_base: bool, package_dirs):
    """Return (model, visual geometry model) of URDF text, or of MJCF text's file ``path``."""
    if is_mjcf(text):
        if not path:
            raise ValueError('MJCF text without its file: give web_view the file (urdf_path)')
        model = build_mjcf_model(path, floating_base)
        try:
            return model, pin.buildGeomFromMJCF(model, path, pin.VISUAL)
        except (RuntimeError, ValueError) as exc:
            raise ValueError(f'MJCF visuals not loadable: {exc}') from exc
    text = resolve_package_uris(text, path, package_dirs)
    try:
        if floating_base:
            model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer())
        else:
            model = pin.buildModelFromXML(text)
        return model, pin.buildGeomFromUrdfString(model, text, pin.VISUAL)
    except (RuntimeError, ValueError) as exc:
        raise ValueError(f'URDF not loadable: {exc}') from exc


class RobotScene:
    def __init__(self, urdf_text: str, urdf_path: str = '', floating_base: bool = False,
                 package_dirs=None):
        """
        Load the model and its visuals from URDF text, or MJCF text and its file.

        ``urdf_path``: where the text came from (``package://`` names are looked up from there;
        MJCF needs it: its meshes are found from its directory); raises ValueError naming what
        cannot be loaded.
        """
        self.model, self.geom_model = _models(urdf_text, urdf_path, floating_base, package_dirs)
        self.floating = floating_base
        self.data = self.model.createData()
        self.geom_data = pin.GeometryData(self.geom_model)
        self.visuals = []
        for g in self.geom_model.geometryObjects:
            verts, faces = _mesh_of(g.geometry)  # a mesh file: scaled by Pinocchio's loader
            self.visuals.append(Visual(g.name, verts, faces, tuple(float(c) for c in g.meshColor)))
        # joint name -> (index in q, 1 for a revolute/prismatic joint, 2 for a continuous one)
        self._slots = {
            self.model.names[j]: (self.model.joints[j].idx_q, self.model.joints[j].nq)
            for j in range(1, self.model.njoints)
            if self.model.joints[j].nq in (1, 2) and self.model.joints[j].nv == 1
        }
        self.q = pin.neutral(self.model)
        self.update({}, None)

    @property
    def joint_names(self) -> list[str]:
        return list(self._slots)

    def update(self, positions: dict, base_pose=None) -> None:
        """
        Set the state: ``positions`` {joint name: position} (other names ignored).

        ``base_pose``: (position (3,), quaternion xyzw (4,)) of a floating base in the world.
        """
        q = self.q
        for name, value in positions.items():
            slot = self._slots.get(name)
            if slot is None or not np.isfinite(value):
                continue
            i, n = slot
            if n == 1:
                q[i] = value
            else:
                q[i], q[i + 1] = np.cos(value), np.sin(value)
        if self.floating and base_pose is not None:
            p, quat = base_pose
            quat = np.asarray(quat, dtype=float)
            if np.all(np.isfinite(p)) and np.linalg.norm(quat) > 0.5:
                q[:3], q[3:7] = p, quat / np.linalg.norm(quat)
        pin.forwardKinematics(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        pin.updateGeometryPlacements(self.model, self.data, self.geom_model, self.geom_data)

    def visual_poses(self) -> list[np.ndarray]:
        """World pose (4x4) of each visual, in the order of :attr:`visuals`."""
        return [m.homogeneous for m in self.geom_data.oMg]

    def frame_pose(self, frame: str) -> np.ndarray:
        """World pose (4x4) of a frame of the model; ``world`` or ``''``: the identity."""
        if frame in ('', 'world'):
            return np.eye(4)
        if not self.model.existFrame(frame):
            raise ValueError(f"unknown frame '{frame}'")
        return self.data.oMf[self.model.getFrameId(frame)].homogeneous

    @property
    def root_frame(self) -> str:
        """Name the URDF's root link (a fixed base sits there: the usual base frame)."""
        return self.model.frames[2].name if self.floating else self.model.frames[1].name
