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
The self pairs collision avoidance leaves out, as MoveIt's setup assistant would (issue 37).

Each reason is checked independently of the code that chose it: coal on the URDF's own collision
meshes (not the constraint's rounded hulls) over postures sampled with another generator.
"""

import logging
import xml.etree.ElementTree as ET

import coal
import numpy as np
import orca_ros as orca
from orca_ros.robot import collision_pairs
from orca_ros.robot.collision_geometry import CollisionGeometry
import pinocchio as pin
import pytest

UR5 = ('ur_description/urdf/ur5_robot.urdf', 'ur_description/srdf/ur5.srdf')
Q_UR5 = np.array([0.0, -1.2, 1.6, -1.9, -1.57, 0.0])  # its working posture (issue 37)


def _robot(example_robot_urdf, rel, q=None):
    robot = orca.RobotModel()
    robot.load_model_from_file(example_robot_urdf(rel))
    if q is not None:
        robot.set_robot_state(q, np.zeros(q.size))
    return robot


def _mesh_distances(model, urdf, link_pairs):
    """Return d(q) -> {(link, link): least distance between the two links' meshes}."""
    share = urdf.split('/example-robot-data/')[0]
    gm = pin.buildGeomFromUrdf(model, urdf, pin.COLLISION, package_dirs=[share])
    gd, data = pin.GeometryData(gm), model.createData()
    objects = gm.geometryObjects
    of = {}
    for i, g in enumerate(objects):
        of.setdefault(collision_pairs.link_of(model, g), []).append(i)

    def distances(q):
        pin.updateGeometryPlacements(model, data, gm, gd, q)
        out = {}
        for a, b in link_pairs:
            best = np.inf
            for i in of[a]:
                for j in of[b]:
                    r = coal.DistanceResult()
                    coal.distance(objects[i].geometry, coal.Transform3s(gd.oMg[i]),
                                  objects[j].geometry, coal.Transform3s(gd.oMg[j]),
                                  coal.DistanceRequest(), r)
                    best = min(best, r.min_distance)
            out[(a, b)] = best
        return out

    return distances


def test_the_ur5_wrist_pair_its_srdf_keeps_is_left_out_as_never(example_robot_urdf, tmp_path,
                                                                monkeypatch):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))
    urdf, srdf = (example_robot_urdf(p) for p in UR5)
    robot = _robot(example_robot_urdf, UR5[0], Q_UR5)
    geom = CollisionGeometry(robot, srdf)
    disabled = {frozenset((e.get('link1'), e.get('link2')))
                for e in ET.parse(srdf).getroot().iter('disable_collisions')}
    # the SRDF leaves the flange's block and the first wrist link watched; they cannot meet
    assert frozenset(('wrist_1_link', 'ee_link')) not in disabled
    assert geom.left_out[('wrist_1_link', 'ee_link')] == 'never'
    assert 'never (1): wrist_1_link/ee_link' in geom.pair_summary
    for pair, why in geom.left_out.items():
        assert (why == 'disabled') == (frozenset(pair) in disabled)
    watched = {collision_pairs.link_pair(robot.model, geom.geom_model, p)
               for p in geom.geom_model.collisionPairs}
    assert not {frozenset(p) for p in watched} & {frozenset(p) for p in geom.left_out}
    # independently: the 'never' pairs' meshes keep apart over other postures; at the start the
    # pair is within the influence distance (10 cm): watched, it had a row from the first cycle
    model = robot.model
    never = [p for p, why in geom.left_out.items() if why == 'never']
    distances = _mesh_distances(model, urdf, never)
    assert distances(Q_UR5)[('wrist_1_link', 'ee_link')] < 0.1
    rng = np.random.default_rng(7)
    lo, hi = collision_pairs._limits(model)
    least = min(min(distances(rng.uniform(lo, hi)).values()) for _ in range(500))
    # twice the rounding of the hulls that were sampled: the meshes' hulls, and so the meshes
    assert least > 2 * geom.rounding - 1e-9
    print(geom.pair_summary, f'least mesh distance of the never pairs: {least * 1e3:.1f} mm')


def test_default_and_always_pairs_and_the_cache(example_robot_urdf, tmp_path, monkeypatch):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))
    rel = 'ur_description/urdf/ur10_robot.urdf'  # no SRDF ships: every pair by sampling
    robot = _robot(example_robot_urdf, rel, Q_UR5)
    geom = CollisionGeometry(robot)
    kinds = set(geom.left_out.values())
    assert kinds <= {'never', 'always', 'default'} and 'always' in kinds
    cached = list((tmp_path / 'orca_ros' / 'collision_pairs').glob('*.json'))
    assert len(cached) == 1
    again = CollisionGeometry(robot)  # from the cache file: the same pairs
    assert again.left_out == geom.left_out
    # an 'always' pair is in contact (rounded hulls) at most postures, as sampled again here
    model, gm = robot.model, geom.geom_model
    full = CollisionGeometry(robot, samples=0)
    always = {p for p, why in geom.left_out.items() if why == 'always'}
    data, gd = model.createData(), pin.GeometryData(full.geom_model)
    lo, hi = collision_pairs._limits(model)
    rng, touching, n = np.random.default_rng(3), {p: 0 for p in always}, 400
    for _ in range(n):
        pin.computeCollisions(model, data, full.geom_model, gd, rng.uniform(lo, hi), False)
        for k, p in enumerate(full.geom_model.collisionPairs):
            pair = collision_pairs.link_pair(model, full.geom_model, p)
            if pair in touching and gd.collisionResults[k].isCollision():
                touching[pair] += 1
    assert min(touching.values()) > 0.8 * n, touching
    assert len(full.geom_model.collisionPairs) > len(gm.collisionPairs)


def test_a_start_in_contact_leaves_the_pair_out_as_default(example_robot_urdf, tmp_path,
                                                           monkeypatch):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))
    rel = 'ur_description/urdf/ur5_robot.urdf'
    robot = _robot(example_robot_urdf, rel)
    model = robot.model
    # fold the forearm back onto the upper arm until their hulls touch
    q = Q_UR5.copy()
    full = CollisionGeometry(robot, samples=0)
    data, gd = model.createData(), pin.GeometryData(full.geom_model)
    for k, p in enumerate(full.geom_model.collisionPairs):
        gd.collisionRequests[k].security_margin = -2 * full.rounding
    for elbow in np.linspace(1.6, 3.1, 61):
        q[2] = elbow
        pin.computeCollisions(model, data, full.geom_model, gd, q, False)
        hit = [collision_pairs.link_pair(model, full.geom_model, p)
               for k, p in enumerate(full.geom_model.collisionPairs)
               if gd.collisionResults[k].isCollision()]
        if hit:
            break
    assert hit, 'no posture in contact found'
    robot.set_robot_state(q, np.zeros(6))
    geom = CollisionGeometry(robot, samples=0)
    for pair in hit:
        assert geom.left_out[pair] == 'default'


def test_the_srdf_written_gives_the_same_pairs(example_robot_urdf, tmp_path, monkeypatch):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))
    urdf, srdf = (example_robot_urdf(p) for p in UR5)
    out = tmp_path / 'ur5_chosen.srdf'
    assert collision_pairs.main([urdf, '--srdf', srdf, '-o', str(out)]) == 0
    written = {frozenset((e.get('link1'), e.get('link2'))): e.get('reason')
               for e in ET.parse(out).getroot().iter('disable_collisions')}
    assert written[frozenset(('wrist_1_link', 'ee_link'))] == 'Never'
    robot = _robot(example_robot_urdf, UR5[0], Q_UR5)
    chosen = CollisionGeometry(robot, srdf)
    from_file = CollisionGeometry(robot, str(out), samples=0)  # nothing sampled: the file's
    assert ({p.first: p.second for p in from_file.geom_model.collisionPairs}
            == {p.first: p.second for p in chosen.geom_model.collisionPairs})
    assert set(from_file.left_out.values()) == {'disabled'}


def test_the_constraint_logs_its_pairs_once(example_robot_urdf, tmp_path, monkeypatch, caplog):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))
    _, srdf = (example_robot_urdf(p) for p in UR5)
    robot = _robot(example_robot_urdf, UR5[0], Q_UR5)
    c = orca.Controller('c', robot)
    col = c.add_constraint(orca.CollisionAvoidanceConstraint('collision', srdf=srdf))
    c.activate_tasks_and_constraints()
    logger = logging.getLogger('orca_ros')
    logger.addHandler(caplog.handler)
    try:
        with caplog.at_level(logging.INFO, logger='orca_ros'):
            for k in range(3):
                assert c.update(k * 1e-3, 1e-3)
    finally:
        logger.removeHandler(caplog.handler)
    lines = [r.getMessage() for r in caplog.records if 'link pairs watched' in r.getMessage()]
    assert len(lines) == 1 and 'wrist_1_link/ee_link' in lines[0] and 'collision' in lines[0]
    assert col.geometry.left_out[('wrist_1_link', 'ee_link')] == 'never'
    with pytest.raises(ValueError, match='pair_samples'):
        orca.CollisionAvoidanceConstraint('bad', pair_samples=-1)


def test_meshes_named_relative_to_their_urdf_load_from_any_directory(tmp_path, monkeypatch):
    """
    pybullet_data's iiwa names its meshes ``meshes/link_0.stl``: relative to the URDF.

    Coal reads a bare name from the working directory; the constraint resolves it against the
    URDF's directory, so the arm's eight links get their own meshes wherever the program runs.
    Each mesh's hull holds every vertex of that mesh file (read here with coal on its own).
    """
    pybullet_data = pytest.importorskip('pybullet_data')
    import os

    urdf = os.path.join(pybullet_data.getDataPath(), 'kuka_iiwa', 'model.urdf')
    names = [m.get('filename') for m in ET.parse(urdf).getroot().iter('mesh')
             if m.get('filename', '').endswith('.stl')]
    assert names and not any(os.path.isabs(n) for n in names)  # relative, as shipped
    monkeypatch.chdir(tmp_path)  # where none of them is
    assert not any(os.path.exists(n) for n in names)
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    geometry = CollisionGeometry(robot, samples=0, cache=False)
    objects = geometry.geom_model.geometryObjects
    assert geometry.n_robot == len(objects) == 8
    loader = coal.MeshLoader()
    for obj in objects:
        assert os.path.isabs(obj.meshPath) and os.path.dirname(obj.meshPath).endswith('meshes')
        mesh = loader.load(obj.meshPath, obj.meshScale)
        vertices = np.asarray(mesh.vertices())
        # the constraint's hull (of the same mesh) contains every vertex: support function
        hull = obj.geometry
        hull_points = np.asarray(hull.points())
        for direction in np.eye(3).tolist() + (-np.eye(3)).tolist():
            d = np.asarray(direction)
            assert (hull_points @ d).max() >= (vertices @ d).max() - 1e-9


def test_a_pair_the_kinematics_keep_within_the_safety_distance_is_left_out_as_near(
        tmp_path, monkeypatch):
    """
    The iiwa's link 5 and flange link 7: within 3 cm of each other in 95 % of the postures.

    The constraint could only hold the arm still where it finds them; left out as ``near`` at a
    safety distance of 3 cm (as MoveIt's ``Always`` in the SRDF written), watched without one.
    What decides is the sampled distance within which 95 % of the postures lie, recomputed here
    from the cache file's share and distance.
    """
    pybullet_data = pytest.importorskip('pybullet_data')
    import json
    import os

    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path))
    urdf = os.path.join(pybullet_data.getDataPath(), 'kuka_iiwa', 'model.urdf')
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    pair = ('lbr_iiwa_link_5', 'lbr_iiwa_link_7')
    watched = CollisionGeometry(robot)  # no safety distance: sampled and cached
    assert pair not in watched.left_out
    (cache,) = list((tmp_path / 'orca_ros' / 'collision_pairs').iterdir())
    share, within = json.loads(cache.read_text())['\n'.join(pair)]
    assert 0.0 < share < collision_pairs.ALWAYS and 0.0 < within < 0.03
    near = CollisionGeometry(robot, near=0.03)  # from the cache
    assert near.left_out[pair] == 'near' and 'near (1): lbr_iiwa_link_5/lbr_iiwa_link_7' in \
        near.pair_summary
    assert set(watched.left_out.items()) < set(near.left_out.items())
    text = collision_pairs.srdf_text('iiwa', near.left_out)
    assert '<disable_collisions link1="lbr_iiwa_link_5" link2="lbr_iiwa_link_7" ' \
           'reason="Always"/>' in text
    # below the pair's sampled distance it is watched again
    assert pair not in CollisionGeometry(robot, near=0.5 * within).left_out
