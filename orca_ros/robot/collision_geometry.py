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
The robot's collision geometry and the obstacles around it, and their distances (Pinocchio, coal).

The geometry is the URDF's ``<collision>`` elements (``package://`` resolved as the simulator does,
:mod:`.urdf_text`), or an MJCF robot's collision geoms (Pinocchio's parser; the file's
``<contact><exclude>`` body pairs left out as an SRDF's disabled pairs are), meshes replaced by
their convex hulls (coal's GJK on convex shapes, far faster than the distance between the
meshes' BVHs). Pairs watched: every two geometries of
different bodies, minus adjacent bodies (a joint between them) and the pairs an SRDF disables
(``disable_collisions``, example-robot-data ships them); plus every obstacle against every robot
geometry. Obstacles are primitives (sphere, box, cylinder, capsule) fixed in the world or to a
link, added, moved and removed at run time.

Per cycle :meth:`CollisionGeometry.closest` places the geometries from the joints' placements the
controller's Pinocchio pass left in Data, discards the pairs whose bounding spheres are further
apart than they may matter (the influence distance, further for a pair closing fast:
:meth:`CollisionGeometry.closing_bound`), and runs coal's distance on the rest (Pinocchio's
``computeDistance`` on the pair, in C++: building coal's transforms and result in Python for
``coal.distance`` costs several times the distance itself): distance, witness points and the normal
from the first body to the second. The compiled cycle screens the pairs and reads the results by
kernel (:mod:`orca_ros.constraint.collision_kernel`); ``version`` counts the rebuilds of
``geom_data`` (obstacles added or removed), after which it takes its views again.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from . import collision_pairs
from .mjcf import mjcf_excluded_pairs
from .urdf_text import resolve_package_uris

SHAPES = {'sphere': 1, 'box': 3, 'cylinder': 2, 'capsule': 2}  # and how many sizes each takes
GJK_TOLERANCE = 1e-9  # [m] (see CollisionGeometry._rebuild)


def make_shape(shape: str, size):
    """
    Return a coal primitive: sphere [radius], box [x, y, z], cylinder or capsule [radius, length].

    Raises ValueError naming what is wrong (an unknown shape, a size not finite and > 0).
    """
    if shape not in SHAPES:
        raise ValueError(f"unknown shape '{shape}' (one of {', '.join(SHAPES)})")
    s = np.asarray(size, dtype=float).reshape(-1)
    if s.size != SHAPES[shape] or not np.all(np.isfinite(s)) or np.any(s <= 0.0):
        raise ValueError(f'{shape} size must be {SHAPES[shape]} finite values > 0, got {size}')
    if shape == 'sphere':
        return coal.Sphere(s[0])
    if shape == 'box':
        return coal.Box(*s)
    if shape == 'cylinder':
        return coal.Cylinder(s[0], s[1])
    return coal.Capsule(s[0], s[1])


def _bounding_sphere(geometry) -> tuple[np.ndarray, float]:
    """(centre, radius) in the geometry's own frame enclosing it."""
    if isinstance(geometry, coal.Sphere):
        return np.zeros(3), geometry.radius
    if isinstance(geometry, coal.Box):
        return np.zeros(3), float(np.linalg.norm(geometry.halfSide))
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        extra = geometry.radius if isinstance(geometry, coal.Capsule) else 0.0
        return np.zeros(3), float(np.hypot(geometry.radius, geometry.halfLength)) + extra
    pts = np.asarray(geometry.points()) if hasattr(geometry, 'points') else None
    if pts is None or not len(pts):
        geometry.computeLocalAABB()
        lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
        return 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    return centre, float(np.linalg.norm(pts - centre, axis=1).max())


def _flat(M: pin.SE3) -> np.ndarray:
    return np.concatenate((M.rotation.reshape(-1, order='F'), M.translation))


def _points(geometry) -> np.ndarray | None:
    """Return the vertices of a convex hull or a box (None for the round primitives)."""
    if isinstance(geometry, coal.Box):
        h = np.asarray(geometry.halfSide)
        return np.array([[x, y, z] for x in (-h[0], h[0]) for y in (-h[1], h[1])
                         for z in (-h[2], h[2])])
    pts = np.asarray(geometry.points()) if hasattr(geometry, 'points') else None
    return pts if pts is not None and len(pts) else None


def _bounding_capsule(geometry) -> np.ndarray:
    """
    [end, end, radius] in the geometry's own frame: a capsule enclosing it.

    A link is long and thin: its bounding sphere holds it loosely, a capsule closely. The axis is
    the vertices' principal one, through the middle of their spread across it; the radius the
    largest distance of a vertex from that axis; each end as far in as still covers every vertex
    (a vertex at t along the axis and rho from it is inside when |t - end| <= sqrt(r^2 - rho^2)).
    """
    if isinstance(geometry, coal.Sphere):
        return np.array([0.0] * 6 + [geometry.radius])
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        h = geometry.halfLength
        return np.array([0.0, 0.0, -h, 0.0, 0.0, h, geometry.radius])
    pts = _points(geometry)
    if pts is None:  # another shape: its bounding sphere
        centre, radius = _bounding_sphere(geometry)
        return np.concatenate((centre, centre, [radius]))
    mean = pts.mean(axis=0)
    axes = np.linalg.eigh(np.cov((pts - mean).T))[1][:, ::-1]  # principal axis first
    local = (pts - mean) @ axes
    middle = 0.5 * (local.min(axis=0) + local.max(axis=0))
    middle[0] = 0.0
    local -= middle
    rho2 = local[:, 1] ** 2 + local[:, 2] ** 2
    r2 = float(rho2.max())
    room = np.sqrt(np.maximum(r2 - rho2, 0.0))
    lo, hi = float(np.max(local[:, 0] - room)), float(np.min(local[:, 0] + room))
    if hi > lo:  # no segment inside: a sphere round its middle
        lo = hi = 0.5 * (lo + hi)
        r2 = float(np.max((local[:, 0] - lo) ** 2 + rho2))
    ends = mean + (middle + np.outer([hi, lo], [1.0, 0.0, 0.0])) @ axes.T
    return np.concatenate((ends[0], ends[1], [np.sqrt(r2)]))


class CollisionGeometry:
    def __init__(self, robot, srdf: str | None = None, package_dirs=None, rounding: float = 0.01,
                 samples: int = collision_pairs.SAMPLES, cache: bool = True, near: float = 0.0):
        """
        Load the robot's collision geometry and its pairs.

        ``srdf``: an SRDF file whose ``disable_collisions`` pairs are left out;
        ``package_dirs``: {package: directory} for ``package://`` names the URDF's location does
        not resolve; ``rounding``: every body is inflated by this radius (coal's swept sphere), so
        that its surface, and the normal of a pair, move continuously as the closest features
        change (on a polyhedral hull the normal jumps from facet to facet); ``samples``: postures
        sampled to leave out the pairs never or always in contact, or always within ``near`` (the
        safety distance of the constraint; :mod:`.collision_pairs`; 0: none), ``cache``: their
        cache file used).
        """
        self.rounding = float(rounding)
        model = robot.model
        excluded = set()
        if robot.mjcf_path is not None:  # its collision geoms; its <exclude> pairs left out
            gm = pin.buildGeomFromMJCF(model, robot.mjcf_path, pin.COLLISION)
            excluded = mjcf_excluded_pairs(robot.mjcf_path)
        elif robot.urdf_xml is not None:
            text = resolve_package_uris(robot.urdf_xml, robot.urdf_path or '', package_dirs)
            gm = pin.buildGeomFromUrdfString(model, text, pin.COLLISION)
        else:
            raise ValueError('the robot has no URDF or MJCF description loaded')
        for g in gm.geometryObjects:
            if hasattr(g.geometry, 'buildConvexHull'):  # a mesh: its convex hull
                g.geometry.buildConvexHull(True, 'Qt')
                g.geometry = g.geometry.convex
            g.geometry.setSweptSphereRadius(self.rounding)
        self.model, self.geom_model = model, gm
        self.n_robot = gm.ngeoms
        parents = model.parents
        for i in range(gm.ngeoms):
            for j in range(i + 1, gm.ngeoms):
                a, b = gm.geometryObjects[i].parentJoint, gm.geometryObjects[j].parentJoint
                if a == b or parents[a] == b or parents[b] == a:
                    continue  # one body, or adjacent bodies
                gm.addCollisionPair(pin.CollisionPair(i, j))
        self.pairs_before_srdf = len(gm.collisionPairs)
        links = {frozenset(collision_pairs.link_pair(model, gm, p)) for p in gm.collisionPairs}
        if srdf is not None:
            pin.removeCollisionPairs(model, gm, srdf)
        collision_pairs.remove_pairs(model, gm, excluded)
        kept = {collision_pairs.link_pair(model, gm, p) for p in gm.collisionPairs}
        #: the robot's link pairs not watched: {(link, link): reason} (see .collision_pairs)
        self.left_out = {tuple(sorted(p)): 'disabled' for p in
                         links - {frozenset(p) for p in kept}}
        start = [robot.get_configuration()] if robot.is_initialized() else []
        self.left_out.update(collision_pairs.left_out(model, gm, start, samples, cache=cache,
                                                      near=near))
        collision_pairs.remove_pairs(model, gm, self.left_out)
        #: one line: the link pairs watched and those left out, by reason
        self.pair_summary = collision_pairs.summary(
            self.left_out, len({collision_pairs.link_pair(model, gm, p)
                                for p in gm.collisionPairs}))
        self.obstacles: dict[str, int] = {}  # name -> geometry index
        self.velocities: dict[str, np.ndarray] = {}  # name -> linear velocity (world) if moving
        self.version = 0
        self._robot_bounds: list = []  # (centre, radius, capsule) of the robot's geometries
        self._rebuild()

    def _rebuild(self) -> None:
        gm = self.geom_model
        self.geom_data = pin.GeometryData(gm)
        for request in self.geom_data.distanceRequests:
            # GJK stops when its distance is this close; its normal is then off by about
            # sqrt(2 tol / d): at coal's 1e-6, up to 4e-3 rad at 10 cm, jumping from one state to
            # the next as the iterations end at other points; the rows follow it. On the
            # Panda going round a ball (test_collision_avoidance.py) that noise stepped the
            # torques; at GJK_TOLERANCE and below only the joints' own kinks remain, and GJK
            # takes no longer there than at coal's default.
            request.gjk_tolerance = GJK_TOLERANCE
        # the bounding volumes (the robot's computed once: a rebuild for an obstacle runs in
        # the control cycle)
        bounds = list(self._robot_bounds)
        for g in gm.geometryObjects[len(bounds):]:
            c, r = _bounding_sphere(g.geometry)
            bounds.append((c, r + self.rounding, _bounding_capsule(g.geometry)))
        self._robot_bounds = bounds[:self.n_robot]
        # each geometry's bounding sphere (centre in its joint's frame, radius with the rounding),
        # capsule ([end, end, radius], in the geometry's frame) and joint: read by the kernels,
        # new arrays at each rebuild (version)
        self.sphere_centre = np.array([b[0] for b in bounds]).reshape(-1, 3)
        self.sphere_radius = np.array([b[1] for b in bounds])
        self.capsule = np.array([b[2] for b in bounds]).reshape(-1, 7)
        self.capsule[:, 6] += self.rounding
        self.joint = [int(g.parentJoint) for g in gm.geometryObjects]
        cp = gm.collisionPairs
        self._first = np.array([p.first for p in cp], dtype=int)
        self._second = np.array([p.second for p in cp], dtype=int)
        self.pairs = [(int(p.first), int(p.second)) for p in cp]  # Python ints: coal's indices
        self.velocity = np.zeros((gm.ngeoms, 3))  # each geometry's: a moving obstacle's, else 0
        # each geometry's placement on its joint [R column-major, p] (the kernels place them)
        self.placement = np.array([_flat(g.placement) for g in gm.geometryObjects]).reshape(-1, 12)
        for name, v in self.velocities.items():
            self.velocity[self.obstacles[name]] = v
        self.version += 1

    # ------------------------------------------------------------------ obstacles
    def add_obstacle(self, name: str, shape: str, size, pose=None, frame: str | None = None):
        """
        Add (or replace) obstacle ``name``: a primitive at ``pose`` (4x4) in the world, or in link.

        ``frame``: a frame of the model (the obstacle moves with it); None or 'world': fixed.
        """
        geometry = make_shape(shape, size)
        geometry.setSweptSphereRadius(self.rounding)
        joint, placement = self._placement(pose, frame)
        if name in self.obstacles:
            self.remove_obstacle(name)
        gm = self.geom_model
        index = gm.addGeometryObject(pin.GeometryObject(f'obstacle:{name}', joint, placement,
                                                        geometry))
        for i in range(self.n_robot):
            if gm.geometryObjects[i].parentJoint != joint:
                gm.addCollisionPair(pin.CollisionPair(i, index))
        self.obstacles[name] = index
        self._rebuild()

    def depth_into_robot(self, data, geometry, pose, frame, beyond: float):
        """
        Return how deep a shape (coal's) placed so goes into the robot's moving bodies: (m, link).

        Only a depth beyond ``beyond`` is looked for ((0, '') else): a pair whose bounding
        spheres overlap by less cannot go that deep (moving one sphere out by its overlap parts
        both), and coal runs on the rest, the most overlapping first. The robot's bodies where
        ``data``'s joint placements (the controller's last pass) put them, without their
        rounding. Bodies fixed to the world (a fixed
        base's) and those of the obstacle's own link are not counted.
        """
        joint, placement = self._placement(pose, frame)
        centre, radius = _bounding_sphere(geometry)
        rounding = self.rounding + geometry.getSweptSphereRadius()
        at = data.oMi[joint] * placement
        centre = at.act(centre)
        objects, oMi = self.geom_model.geometryObjects, data.oMi
        bodies = [i for i in range(self.n_robot) if objects[i].parentJoint not in (0, joint)]
        if not bodies:
            return 0.0, ''
        places = [oMi[objects[i].parentJoint] * objects[i].placement for i in bodies]
        centres = np.array([M.act(self.sphere_centre[i]) for M, i in zip(places, bodies)])
        overlap = (radius + self.sphere_radius[bodies] - rounding
                   - np.linalg.norm(centres - centre, axis=1))
        deepest = (0.0, '')
        request = coal.DistanceRequest()
        for k in np.argsort(-overlap):
            if overlap[k] <= max(beyond, deepest[0]):
                break
            obj = objects[bodies[k]]
            result = coal.DistanceResult()
            coal.distance(obj.geometry, coal.Transform3s(places[k]), geometry,
                          coal.Transform3s(at), request, result)
            depth = -(result.min_distance + rounding)  # (the bodies' rounding not counted)
            if depth > max(beyond, deepest[0]):
                deepest = (float(depth), self.model.frames[obj.parentFrame].name)
        return deepest

    def move_obstacle(self, name: str, pose, frame: str | None = None, velocity=None) -> None:
        """
        Move obstacle ``name`` to ``pose`` (in the world, or in ``frame``).

        ``velocity``: its linear velocity (world axes) from now on, for the rate of its distances
        (None: at rest).
        """
        if name not in self.obstacles:
            raise KeyError(f"no obstacle '{name}'")
        obj = self.geom_model.geometryObjects[self.obstacles[name]]
        joint, placement = self._placement(pose, frame)
        if joint != obj.parentJoint:
            raise ValueError(f"obstacle '{name}': move it within its frame, or add it again")
        v = None if velocity is None else np.asarray(velocity, dtype=float).reshape(3)
        if v is not None and not np.isfinite(v).all():
            raise ValueError(f"obstacle '{name}': velocity must be finite")
        obj.placement = placement
        self.placement[self.obstacles[name]] = _flat(placement)
        if v is None:
            self.velocities.pop(name, None)
            self.velocity[self.obstacles[name]] = 0.0
        else:
            self.velocities[name] = v
            self.velocity[self.obstacles[name]] = v

    def remove_obstacle(self, name: str) -> None:
        gm = self.geom_model
        index = self.obstacles.pop(name)
        self.velocities.pop(name, None)
        gm.removeGeometryObject(f'obstacle:{name}')
        self.obstacles = {n: (i - 1 if i > index else i) for n, i in self.obstacles.items()}
        self._rebuild()

    def _placement(self, pose, frame):
        T = np.eye(4) if pose is None else np.asarray(pose, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError('an obstacle pose must be a finite 4x4 transform')
        placement = pin.SE3(T[:3, :3], T[:3, 3])
        if frame in (None, '', 'world'):
            return 0, placement
        if not self.model.existFrame(frame):
            raise ValueError(f"unknown frame '{frame}'")
        f = self.model.frames[self.model.getFrameId(frame)]
        return f.parentJoint, f.placement * placement

    # ------------------------------------------------------------------ distances
    def closing_bound(self, data, centres: np.ndarray) -> np.ndarray:
        """
        Return, per pair, a bound on how fast its distance can shrink (m/s).

        With W = V_b - V_a the relative velocity field of the pair's bodies, the distance's rate
        is n . (V_b(p2) - V_a(p1)) = n . W(p1) (the rest, w_b x (p2 - p1), is normal to n), and
        W(p1) differs from W at the first body's centre by at most |w_b - w_a| times its radius
        (likewise from the second's). Links moving together (a whole arm turning on its base)
        have a small bound, though each moves fast. ``centres``: the geometries' sphere centres.
        """
        v = data.v
        ng = len(self.joint)
        vc, w = self.velocity.copy(), np.zeros((ng, 3))
        for g, j in enumerate(self.joint):
            if j:
                M = data.oMi[j]
                w[g] = M.rotation @ v[j].angular
                vc[g] += M.rotation @ v[j].linear + np.cross(w[g], centres[g] - M.translation)
        a, b = self._first, self._second
        dw = np.linalg.norm(w[b] - w[a], axis=1)
        at_a = vc[b] + np.cross(w[b], centres[a] - centres[b]) - vc[a]
        at_b = vc[b] - vc[a] - np.cross(w[a], centres[b] - centres[a])
        return np.minimum(np.linalg.norm(at_a, axis=1) + dw * self.sphere_radius[a],
                          np.linalg.norm(at_b, axis=1) + dw * self.sphere_radius[b])

    def closest(self, data, limit_of):
        """
        Return the pairs that may matter: [(distance, pair index, p1, p2, normal)], closest first.

        Those closer than ``limit_of(closing)``, of the bound on each pair's closing speed
        (:meth:`closing_bound`). From the joints' placements and velocities in ``data`` (the
        controller's pass); witness points p1 on the pair's first geometry, p2 on its second, the
        normal from the first to the second (world).
        """
        gm, gd = self.geom_model, self.geom_data
        pin.updateGeometryPlacements(self.model, data, gm, gd)
        if not len(self._first):
            return []
        oMg = gd.oMg
        centres = np.array([oMg[i].act(self.sphere_centre[i]) for i in range(gm.ngeoms)])
        limit = limit_of(self.closing_bound(data, centres))
        gap = (np.linalg.norm(centres[self._first] - centres[self._second], axis=1)
               - self.sphere_radius[self._first] - self.sphere_radius[self._second])
        out = []
        for k in np.flatnonzero(gap < limit).tolist():
            res = pin.computeDistance(gm, gd, k)
            d, normal = res.min_distance, np.array(res.normal)
            if d < limit[k] and np.isfinite(normal).all():  # (no row from a NaN)
                p1, p2 = np.array(res.getNearestPoint1()), np.array(res.getNearestPoint2())
                out.append((d, k, p1, p2, normal))
        out.sort(key=lambda e: e[0])
        return out

    def velocity_of(self, pair: int) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Return the linear velocities of the pair's moving obstacles (None for other bodies)."""
        objects, (i, j) = self.geom_model.geometryObjects, self.pairs[pair]
        return tuple(self.velocities.get(objects[k].name[len('obstacle:'):])
                     if k >= self.n_robot else None for k in (i, j))

    def is_self_pair(self, pair: int) -> bool:
        """Tell whether a pair is two of the robot's bodies (else a body and an obstacle)."""
        return self.pairs[pair][1] < self.n_robot

    def joints_of(self, pair: int) -> tuple[int, int]:
        objects, (i, j) = self.geom_model.geometryObjects, self.pairs[pair]
        return objects[i].parentJoint, objects[j].parentJoint

    def names_of(self, pair: int) -> tuple[str, str]:
        objects, (i, j) = self.geom_model.geometryObjects, self.pairs[pair]
        return objects[i].name, objects[j].name
