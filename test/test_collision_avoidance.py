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
Collision avoidance (CollisionAvoidanceConstraint): its pairs, its obstacles, the Panda and a ball.

Distances are measured independently of the constraint: coal on the URDF's own collision meshes
(not the constraint's rounded convex hulls) and the ball, on the closed loop's state.
"""

import contextlib

import coal
import numpy as np
import orca_ros as orca
from orca_ros.examples.common import integrate
from orca_ros.robot.collision_geometry import CollisionGeometry
import pinocchio as pin
import pytest

SAFETY = 0.02  # the constraint's default safety distance


def _panda(example_robot_urdf):
    urdf = example_robot_urdf('panda_description/urdf/panda.urdf')
    srdf = example_robot_urdf('panda_description/srdf/panda.srdf')
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    return robot, urdf, srdf


def test_pairs_leave_out_one_body_adjacent_bodies_and_the_srdf_pairs(example_robot_urdf):
    import xml.etree.ElementTree as ET

    robot, urdf, srdf = _panda(example_robot_urdf)
    model = robot.model
    geom = CollisionGeometry(robot, srdf)
    gm = geom.geom_model
    disabled = {frozenset((e.get('link1'), e.get('link2')))
                for e in ET.parse(srdf).getroot().iter('disable_collisions')}
    link_of = {g.name: model.frames[g.parentFrame].name for g in gm.geometryObjects}
    pairs = [(gm.geometryObjects[p.first], gm.geometryObjects[p.second])
             for p in gm.collisionPairs]
    assert 0 < len(pairs) < geom.pairs_before_srdf
    for a, b in pairs:
        ja, jb = a.parentJoint, b.parentJoint
        assert ja != jb and model.parents[ja] != jb and model.parents[jb] != ja
        assert frozenset((link_of[a.name], link_of[b.name])) not in disabled
    print(f'{len(pairs)} pairs of {geom.pairs_before_srdf} (SRDF: {len(disabled)} disabled)')


def test_obstacles_are_added_moved_removed_and_bad_ones_refused(example_robot_urdf):
    robot, _, srdf = _panda(example_robot_urdf)
    geom = CollisionGeometry(robot, srdf)
    n = len(geom.geom_model.collisionPairs)
    # an obstacle fixed in the world is watched against every body that moves (the Panda's
    # link0 is welded to the world: the pair could never change)
    moving = sum(g.parentJoint != 0 for g in geom.geom_model.geometryObjects)
    T = np.eye(4)
    T[:3, 3] = [0.5, 0.0, 0.5]
    geom.add_obstacle('ball', 'sphere', [0.1], T)
    geom.add_obstacle('wall', 'box', [0.1, 1.0, 1.0], T, frame='world')
    assert len(geom.geom_model.collisionPairs) == n + 2 * moving
    T[0, 3] = 0.7
    geom.move_obstacle('ball', T)
    geom.remove_obstacle('wall')
    assert set(geom.obstacles) == {'ball'}
    assert len(geom.geom_model.collisionPairs) == n + moving
    for shape, size, frame, match in (('cone', [1.0], None, "unknown shape 'cone'"),
                                      ('sphere', [np.nan], None, 'finite values > 0'),
                                      ('box', [0.1, 0.1], None, '3 finite values'),
                                      ('sphere', [-0.1], None, '> 0'),
                                      ('sphere', [0.1], 'no_such_link', 'unknown frame')):
        with pytest.raises(ValueError, match=match):
            geom.add_obstacle('bad', shape, size, T, frame)
    assert set(geom.obstacles) == {'ball'}


def _ball_run(example_robot_urdf, with_constraint, pybullet=False, tmp_path=None, each=None):
    """
    Sweep the hand sideways past a ball of 10 cm radius placed on its straight path.

    Its reference moves along the straight line from start to target (minimum jerk, 2 s), then
    stays; 3 s closed on the rigid-body model, or in PyBullet (the ball a body there too). Returns
    the least distance between the Panda's collision meshes and the ball (every 10 cycles), the
    failed cycles, the final hand error and the largest torque step. ``each(k, c, col, redo)``:
    called after each cycle's update (``redo`` updates again).
    """
    robot, urdf, srdf = _panda(example_robot_urdf)
    model = robot.model
    q0 = np.array([-0.7, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])
    q1 = q0.copy()
    q1[0] = 0.7
    data = model.createData()
    hand = model.getFrameId('panda_hand')

    def hand_pose(q):
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[hand].homogeneous.copy()

    T0, T1 = hand_pose(q0), hand_pose(q1)
    centre = 0.5 * (T0[:3, 3] + T1[:3, 3])  # on the straight path
    robot.set_robot_state(q0, np.zeros(model.nv))
    c = orca.Controller('c', robot)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('panda_hand')
    ee.servo_controller().pid().set_proportional_gain([100.0] * 6)
    ee.servo_controller().pid().set_derivative_gain([20.0] * 6)
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(1e-3)
    posture.set_desired(q0)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position')
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity')
    ball = np.eye(4)
    ball[:3, 3] = centre
    col = None
    if with_constraint:
        col = c.add_constraint(orca.CollisionAvoidanceConstraint('collision', srdf=srdf))
        col.add_obstacle('ball', 'sphere', [0.1], ball)
    c.activate_tasks_and_constraints()
    # the independent measure: the URDF's meshes (BVH), not the constraint's rounded hulls
    share = urdf.split('/example-robot-data/')[0]  # the package's parent directory
    gm = pin.buildGeomFromUrdf(model, urdf, pin.COLLISION, package_dirs=[share])
    gd, gdata = pin.GeometryData(gm), model.createData()
    sphere, at = coal.Sphere(0.1), coal.Transform3s(np.eye(3), centre)

    def distance(q):
        pin.updateGeometryPlacements(model, gdata, gm, gd, q)
        best = np.inf
        for i, g in enumerate(gm.geometryObjects):
            r = coal.DistanceResult()
            coal.distance(g.geometry, coal.Transform3s(gd.oMg[i]), sphere, at,
                          coal.DistanceRequest(), r)
            best = min(best, r.min_distance)
        return best

    q, v, dt = q0.copy(), np.zeros(model.nv), 1e-3
    least, failures, step, tau = np.inf, 0, 0.0, None
    with contextlib.ExitStack() as stack:
        if pybullet:
            sim, names, by_name, server = _pybullet_panda(stack, urdf, tmp_path, q0, centre)
        for k in range(3000):
            s = min(1.0, k * dt / 2.0)
            T = T0.copy()
            T[:3, 3] += (10 * s**3 - 15 * s**4 + 6 * s**5) * (T1[:3, 3] - T0[:3, 3])
            ee.servo_controller().set_desired(T)
            if pybullet:
                q, v = sim.get_joint_positions(by_name), sim.get_joint_velocities(by_name)
            robot.set_robot_state(q, v)
            failures += not c.update(k * dt, dt)
            if each is not None:
                each(k, c, col, lambda: c.update(k * dt, dt))
            if tau is not None:
                step = max(step, float(np.abs(c.get_joint_torque_command() - tau).max()))
            tau = c.get_joint_torque_command().copy()
            if pybullet:
                sim.set_joint_torque_command(c.get_joint_torque_command(), by_name)
                server.step()
                q = sim.get_joint_positions(by_name)
            else:
                q, v = integrate(robot, q, v, c.get_joint_torque_command(), dt)
            if k % 10 == 0:
                least = min(least, distance(q))
    return least, failures, float(np.linalg.norm(hand_pose(q)[:3, 3] - T1[:3, 3])), step


def _pybullet_panda(stack, urdf, tmp_path, q0, centre):
    """Load the Panda (meshes resolved) and a static 10 cm ball at ``centre`` into PyBullet."""
    import pybullet as pb
    from orca_ros.robot.urdf_text import resolve_package_uris
    from orca_ros.sim import SimServer

    with open(urdf) as fh:
        text = resolve_package_uris(fh.read(), urdf)
    path = tmp_path / 'panda.urdf'
    path.write_text(text)
    server = stack.enter_context(SimServer(time_step=1e-3, ground_plane=False))
    sim = server.insert_model_from_urdf_file(str(path), fixed_base=True)
    names = [f'panda_joint{i}' for i in range(1, 8)]
    names += ['panda_finger_joint1', 'panda_finger_joint2']
    by_name = sim.joint_map(names)
    sim.set_model_configuration(names, q0)
    c = server.client
    ball = c.createCollisionShape(shapeType=pb.GEOM_SPHERE, radius=0.1)
    c.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=ball, basePosition=list(centre))
    return sim, names, by_name, server


# without the constraint: on the rigid-body model the hand goes through the ball (measured
# -100 mm); in PyBullet, where the ball is a body, it hits it (-0.7 mm: the contact) and is
# pushed round it. A hit is closer than 2 mm.
HIT = {False: 0.0, True: 2e-3}


@pytest.mark.parametrize('pybullet', [False, True], ids=['rigid_model', 'pybullet'])
def test_the_hand_goes_round_a_ball_on_its_path(example_robot_urdf, tmp_path, pybullet):
    """
    Go round the ball: never closer than the safety distance, no failure, the target reached.

    Without the constraint the same run hits the ball. Measured (this test's print): with, 40 mm
    at the least (the constraint keeps 20 mm between bodies it inflates by 10 mm each).
    """
    out = {flag: _ball_run(example_robot_urdf, flag, pybullet, tmp_path) for flag in (False, True)}
    for flag, (least, failures, error, step) in out.items():
        print(f'constraint {flag}: least distance {least * 1e3:.1f} mm, {failures} failures, '
              f'final hand error {error * 1e3:.2f} mm, largest torque step {step:.2f} Nm')
    least, failures, error, step = out[True]
    assert least >= SAFETY - 1e-3
    assert failures == 0
    assert error < 1e-3  # round the ball, to the target
    assert out[False][0] < HIT[pybullet]  # without: into the ball
    # 2.95 / 2.94 Nm measured: the joints' velocity limits binding and letting go after the
    # detour; what pairs entering and leaving do is the next test's (0.000 Nm measured). 12.5
    # with 8 rows, a finger pair entering the budget already binding (CollisionAvoidance-
    # Constraint's docstring): a guard against that
    assert step < 3.5, f'{step:.2f} Nm in one cycle'


@pytest.mark.parametrize('pybullet', [False, True], ids=['rigid_model', 'pybullet'])
def test_pairs_entering_and_leaving_step_the_torques_by_at_most_2_nm(example_robot_urdf,
                                                                     tmp_path, pybullet):
    """
    Round the ball: what each pair entering or leaving the rows does to the torques (issue 21).

    The run's largest steps (2.95 Nm, the print) come from the joints' velocity limits binding
    and letting go while the arm catches up with its reference after the detour (at t = 1.62 s
    and 1.95 s; up to 9.6 Nm without the velocity limits). At each cycle a pair enters, the
    same cycle is solved again without its row: the torques it changes are its step. A pair
    leaves with the row it had in its last cycle; one not binding there (slack > 0: the QP's
    optimum is unique) changes nothing when it goes.
    """
    last, effects, leaving, replayed = {}, [], [], []

    def each(k, c, col, redo):
        tau = c.get_joint_torque_command().copy()
        rows = {(a, b): i for i, (a, b, _) in enumerate(col.last_pairs)}
        x = c.get_reduced_solution()
        slack = {p: float(col.C[i] @ x - col.lb[i]) for p, i in rows.items()}
        entering = set(rows) - set(last)
        if last:
            leaving.extend(last[p] for p in set(last) - set(rows))
        last.clear()
        last.update(slack)
        if not entering or k == 0:
            return
        own = col.update

        def without(t, dt):  # the update, the entering pairs' rows taken out
            own(t, dt)
            for i, (a, b, _) in enumerate(col.last_pairs):
                if (a, b) in entering:
                    col.C[i], col.lb[i] = 0.0, -np.inf

        col.update = without
        try:
            redo()
            effects.append(float(np.abs(c.get_joint_torque_command() - tau).max()))
        finally:
            del col.update
        redo()  # the cycle as it was: nothing of the second solve is left in the run
        replayed.append(float(np.abs(c.get_joint_torque_command() - tau).max()))

    least, failures, error, step = _ball_run(example_robot_urdf, True, pybullet, tmp_path, each)
    print(f'{len(effects)} cycles with pairs entering: largest step from them '
          f'{max(effects):.3f} Nm; {len(leaving)} pairs left, least slack of their last row '
          f'{min(leaving):.3f} m/s^2; largest step of the run {step:.2f} Nm')
    assert least >= SAFETY - 1e-3 and failures == 0 and error < 1e-3
    assert len(effects) > 5 and len(leaving) > 5  # pairs did come and go
    assert max(replayed) < 1e-9
    assert max(effects) <= 2.0
    assert min(leaving) > 0.0


def test_collision_avoidance_from_yaml(example_robot_urdf):
    """type: collision_avoidance with its settings, an SRDF found next to the URDF, obstacles."""
    from orca_ros.configuration import build_from_config, ConfigError

    urdf = example_robot_urdf('panda_description/urdf/panda.urdf')
    cc = {'type': 'collision_avoidance', 'srdf': '../srdf/panda.srdf', 'safety_distance': 0.03,
          'max_pairs': 4, 'obstacles': ['table', 'ball'],
          'table': {'shape': 'box', 'size': [1.0, 1.0, 0.05], 'position': [0.5, 0.0, -0.05]},
          'ball': {'shape': 'sphere', 'size': [0.05], 'position': [0.0, 0.0, 0.1],
                   'frame': 'panda_hand'}}
    cfg = {'urdf_path': urdf, 'joints': [f'panda_joint{i}' for i in range(1, 8)],
           'constraints': {'names': ['collision'], 'collision': cc}}
    setup = build_from_config(cfg)
    col = setup.controller.get_constraint('collision')
    assert isinstance(col, orca.CollisionAvoidanceConstraint)
    assert (col.safety_distance, col.max_pairs, col.rows()) == (0.03, 4, 4)
    assert col.obstacle_names() == ['ball', 'table']
    assert col.srdf.endswith('panda.srdf')
    for change, match in ((('table', 'shape', 'cone'), "obstacle 'table': unknown shape"),
                          (('collision', 'srdf', 'none.srdf'), "SRDF 'none.srdf' not found"),
                          (('collision', 'safety_distance', 1.0), 'safety distance')):
        bad = {k: (dict(v) if isinstance(v, dict) else v) for k, v in cc.items()}
        where = bad if change[0] == 'collision' else bad[change[0]]
        where[change[1]] = change[2]
        cfg['constraints']['collision'] = bad
        with pytest.raises(ConfigError, match=match):
            build_from_config(cfg)


def test_diagnose_names_the_collision_constraint(example_robot_urdf):
    """
    A hand inside the safety distance of a ball, and joints held by hard acceleration limits.

    The constraint asks the hand to move away, the limits forbid any acceleration: infeasible;
    ``diagnose()`` names both. And a target behind the ball: the constraint holds the task back.
    """
    robot, _, srdf = _panda(example_robot_urdf)
    model = robot.model
    q = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])
    robot.set_robot_state(q, np.zeros(model.nv))
    hand = robot.get_frame_pose('panda_hand')[:3, 3]
    c = orca.Controller('c', robot)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('panda_hand')
    ee.servo_controller().pid().set_proportional_gain([100.0] * 6)
    col = c.add_constraint(orca.CollisionAvoidanceConstraint('collision', srdf=srdf))
    ball = np.eye(4)
    ball[:3, 3] = hand + [0.13, 0.0, 0.0]  # the hand within the safety distance of its surface
    col.add_obstacle('ball', 'sphere', [0.1], ball)
    held = c.add_constraint(orca.JointAccelerationLimitConstraint, 'held')
    held.set_limits(-1e-3, 1e-3)
    c.activate_tasks_and_constraints()
    assert not c.update(0.0, 1e-3)
    d = c.diagnose()
    assert not d.feasible and set(d.conflicting_constraints) == {'collision', 'held'}, d.text()
    # the collision constraint says which pairs: the hand's, within the safety distance
    print(d.text())
    assert 'obstacle:ball' in d.details['collision'] and 'hand' in d.details['collision']
    assert f"collision ({d.details['collision']})" in d.text()
    # without the hard limits: a target through the ball; the constraint keeps the hand back
    c.remove_constraint('held')
    target = robot.get_frame_pose('panda_hand')
    target[:3, 3] += [0.3, 0.0, 0.0]
    ee.servo_controller().set_desired(target)
    assert c.update(0.001, 1e-3)
    d = c.diagnose()
    assert ('ee', 'collision') in [(t, k) for t, k, _ in d.blocked_tasks], d.text()
