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
A flat rigid contact as one 6-D wrench with its exact wrench cone.

For a foot sole, or a hand flat on a table.

Several point contacts at the corners of a sole
(:func:`orca_ros.constraint.contact.surface_contact`) describe the same physics but cost 6
variables and 3 existence rows per corner, and the existence rows of a rigid sole are redundant (a
rigid body has 6 degrees of freedom, not 3 per corner: with four corners, 12 rows of rank 6).
Solvers then see rank-deficient equalities; ProxQP declared such feasible problems infeasible.

Here the sole owns one wrench w = [f, m] (world axes, at the frame's origin) and 6 existence rows
(the frame does not accelerate: J nu_dot + J_dot nu = 0). The set of wrenches the corners can
transmit -- the sum of one force per corner, each in a pyramid of ``number_of_faces`` edges on the
friction cone of coefficient mu - margin -- is a polyhedral cone in wrench space (the contact
wrench cone: friction, centre of pressure inside the sole, torsional friction). Its face form F
w_local <= 0 is computed once, at configuration, from its generators [e_k; p_i x e_k] with Qhull
(scipy): the generators are cut by the plane f_z = 1, the facets of their convex hull are the
cone's faces. For a rectangle with 4-edge pyramids: 16 faces (the closed form of Caron, Pham,
Nakamura, ICRA 2015). Every cycle the faces are rotated into world axes (two 3x3 products).

Normal force: f_min <= n . f <= f_max(t), ramped on activation and deactivation as for point
contacts.
"""

from __future__ import annotations

import numpy as np

from .contact import ContactBase, ContactExistenceCondition, NormalForceRamp


def contact_wrench_cone(points, mu: float, n_edges: int = 4) -> np.ndarray:
    """
    Faces F (k x 6) of the wrench cone of a flat contact with normal +z in its own frame.

    F [f; m] <= 0 for every wrench (force f, moment m about the frame's origin) that forces in the
    friction pyramids (edges on the cone of coefficient ``mu``) at ``points`` (n x 3, z = 0) can
    produce.
    """
    from scipy.spatial import ConvexHull  # noqa: PLC0415 - configuration time only

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    if pts.shape[0] < 3:
        raise ValueError(
            'a surface contact needs at least 3 points (use Contact for a point contact)'
        )
    ang = (
        2.0 * np.pi * (np.arange(n_edges) + 0.5) / n_edges
    )  # as Contact's pyramid: a face along each axis
    edges = np.column_stack((mu * np.cos(ang), mu * np.sin(ang), np.ones(n_edges)))  # f_z = 1
    gens = np.array([np.concatenate((e, np.cross(p, e))) for p in pts for e in edges])
    rest = [0, 1, 3, 4, 5]
    hull = ConvexHull(gens[:, rest])
    faces = []
    for (
        eq
    ) in hull.equations:  # a . y + b <= 0 inside, y = w_rest / f_z  ->  a . w_rest + b f_z <= 0
        row = np.zeros(6)
        row[rest] = eq[:5]
        row[2] = eq[5]
        faces.append(row / np.linalg.norm(row))
    faces = np.unique(np.round(np.array(faces), 10), axis=0)  # Qhull splits non-simplicial facets
    return faces


class SurfaceContact(NormalForceRamp, ContactBase):
    existence_rows = 6

    def __init__(
        self,
        name: str,
        frame: str | None = None,
        points=None,
        friction_coefficient: float = 0.6,
        number_of_faces: int = 4,
        margin: float = 0.0,
        maximum_normal_force: float = 1000.0,
        minimum_normal_force: float = 0.0,
    ):
        super().__init__(name)
        if points is None:
            raise ValueError(f"surface contact '{name}': the sole's points (corners) are needed")
        if not (np.isfinite(friction_coefficient) and friction_coefficient > 0.0):
            raise ValueError(f"surface contact '{name}': friction coefficient must be > 0")
        if not 0.0 <= margin < friction_coefficient:
            raise ValueError(f"surface contact '{name}': margin must be in [0, mu)")
        self.points = np.asarray(points, dtype=float).reshape(-1, 3)
        if np.ptp(self.points[:, 2]) > 1e-9:
            raise ValueError(
                f"surface contact '{name}': the points must lie in the frame's z = const plane"
            )
        self.mu, self.margin, self.n_faces = (
            float(friction_coefficient),
            float(margin),
            int(number_of_faces),
        )
        self.set_maximum_normal_force(maximum_normal_force)
        self.minimum_normal_force = max(0.0, float(minimum_normal_force))
        # the cone about the frame's origin: points shifted to the sole plane's height are what
        # matters
        self.faces_local = contact_wrench_cone(self.points, self.mu - self.margin, self.n_faces)
        z = self.points[0, 2]
        if (
            z != 0.0
        ):  # moments about the origin of a sole below it: m_origin = m_plane + (0, 0, z) x f
            shift = np.eye(6)
            shift[3:, :3] = -np.array([[0.0, -z, 0.0], [z, 0.0, 0.0], [0.0, 0.0, 0.0]])
            self.faces_local = self.faces_local @ shift
        self._rot = np.zeros((6, 6))
        self.existence = ContactExistenceCondition(f'{name}_existence', self)
        self.wrench_lower[:] = -np.inf
        self.wrench_upper[:] = np.inf
        if frame is not None:
            self.set_contact_frame(frame)

    def rows(self) -> int:
        return self.faces_local.shape[0] + 1

    @property
    def support_point_count(self) -> int:
        return self.points.shape[0]

    def support_points(self) -> np.ndarray:
        """Return the sole's corners in the world (n x 3)."""
        T = self.robot.world_frame_placement(self.fid)
        return self.points @ T[:3, :3].T + T[:3, 3]

    def contact_normal_world(self) -> np.ndarray:
        return self.robot.world_frame_terms(self.fid)[0][:3, 2]

    def existence_terms(self):
        _, J, _, bias = self.robot.world_frame_terms(self.fid)
        return J, bias

    def fill_wrench_jacobian(self, out: np.ndarray) -> None:
        out[:] = self.robot.world_frame_terms(self.fid)[1]

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        ws = self.wrench_slice()
        R = self.robot.world_frame_terms(self.fid)[0][:3, :3]
        k = self.faces_local.shape[0]
        C = self.C
        # faces in world axes: F_local [R^T f; R^T m] (one product with blockdiag(R^T, R^T))
        Rt = self._rot
        Rt[:3, :3] = R.T
        Rt[3:, 3:] = R.T
        C[:k, ws] = self.faces_local @ Rt
        self.ub[:k] = 0.0
        C[k, ws.start: ws.start + 3] = R[:, 2]
        bound = self.normal_force_bound()
        self.lb[k] = min(self.minimum_normal_force * self.get_ramp_value(), bound)
        self.ub[k] = bound
        self.settle_ramp()
