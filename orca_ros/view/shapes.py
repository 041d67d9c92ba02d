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
"""URDF primitives as triangle meshes (vertices (n, 3), faces (m, 3)), centred on their origin."""

from __future__ import annotations

import numpy as np


def box(size) -> tuple[np.ndarray, np.ndarray]:
    """Box of full extents ``size`` (x, y, z)."""
    h = 0.5 * np.asarray(size, dtype=float)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    faces = np.array([
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # -x, +x
        [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # -y, +y
        [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # -z, +z
    ])
    return corners * h, faces


def cylinder(radius: float, length: float, segments: int = 32):
    """Cylinder along z: ``radius``, full ``length``, closed by two discs."""
    a = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    ring = np.stack((radius * np.cos(a), radius * np.sin(a)), axis=1)
    z = 0.5 * length
    verts = np.vstack((
        np.column_stack((ring, np.full(segments, -z))),
        np.column_stack((ring, np.full(segments, z))),
        [[0.0, 0.0, -z], [0.0, 0.0, z]],
    ))
    i = np.arange(segments)
    j = (i + 1) % segments
    bottom, top = 2 * segments, 2 * segments + 1
    faces = np.vstack((
        np.column_stack((i, j, j + segments)),
        np.column_stack((i, j + segments, i + segments)),
        np.column_stack((np.full(segments, bottom), j, i)),
        np.column_stack((np.full(segments, top), i + segments, j + segments)),
    ))
    return verts, faces


def sphere(radius: float, rings: int = 12, segments: int = 24, stretch: float = 0.0):
    """
    Sphere of ``radius`` (a UV sphere).

    ``stretch`` > 0: a capsule along z, its two halves ``stretch`` apart.
    """
    verts = [[0.0, 0.0, -radius - 0.5 * stretch]]
    for k in range(1, rings):
        phi = np.pi * k / rings - 0.5 * np.pi
        a = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
        z = radius * np.sin(phi) + (0.5 if phi > 0 else -0.5) * stretch
        r = radius * np.cos(phi)
        verts.extend(np.column_stack((r * np.cos(a), r * np.sin(a), np.full(segments, z))))
    verts.append([0.0, 0.0, radius + 0.5 * stretch])
    faces = []
    i = np.arange(segments)
    j = (i + 1) % segments
    faces.append(np.column_stack((np.zeros(segments, int), 1 + j, 1 + i)))
    for k in range(rings - 2):
        a, b = 1 + k * segments, 1 + (k + 1) * segments
        faces.append(np.column_stack((a + i, a + j, b + j)))
        faces.append(np.column_stack((a + i, b + j, b + i)))
    last = 1 + (rings - 2) * segments
    faces.append(np.column_stack((np.full(segments, len(verts) - 1), last + i, last + j)))
    return np.asarray(verts, dtype=float), np.vstack(faces)


def arrow(length: float, shaft_radius: float, head_radius: float, head_length: float,
          segments: int = 16):
    """
    Arrow along +z from the origin to ``length``: a shaft and a cone for its head.

    The head is at most half the arrow (short arrows keep their proportions).
    """
    length = max(float(length), 1e-6)
    head = min(head_length, 0.5 * length)
    shaft_v, shaft_f = cylinder(shaft_radius, length - head, segments)
    shaft_v = shaft_v + [0.0, 0.0, 0.5 * (length - head)]
    a = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    ring = np.column_stack((head_radius * np.cos(a), head_radius * np.sin(a),
                            np.full(segments, length - head)))
    cone_v = np.vstack((ring, [[0.0, 0.0, length - head], [0.0, 0.0, length]]))
    i = np.arange(segments)
    j = (i + 1) % segments
    base, tip = segments, segments + 1
    cone_f = np.vstack((np.column_stack((i, j, np.full(segments, tip))),
                        np.column_stack((np.full(segments, base), j, i))))
    return np.vstack((shaft_v, cone_v)), np.vstack((shaft_f, cone_f + len(shaft_v)))


def z_onto(direction) -> np.ndarray:
    """Rotation (3x3) taking +z onto ``direction`` (the identity for a zero one)."""
    d = np.asarray(direction, dtype=float)
    n = np.linalg.norm(d)
    if n < 1e-12:
        return np.eye(3)
    d = d / n
    v, c = np.cross([0.0, 0.0, 1.0], d), d[2]
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + k + k @ k / (1.0 + c)
