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
Collision avoidance from any start: a self pair found inside its safety distance (issue 37).

The UR5 of example-robot-data with its own SRDF at its working posture, the shipped lwr
configuration's tasks and limits plus a collision constraint whose safety distance (4 cm) the pair
wrist_1_link / ee_link is inside from the start (``pair_samples: 0``: the pair is kept, as before
the pairs were chosen by sampling). The hand is sent 10 cm forward along a trajectory. Held where
it was found, the pair does not close further, and nothing is pushed apart: no failed cycle, no
torque step. Pushed out at the constraint's deceleration instead (the behaviour before), every
cycle fails and the hand stays 18 cm short. Distances measured independently: coal on the URDF's
own meshes.
"""

import coal
import numpy as np
import orca_ros as orca
from orca_ros.configuration.controller_builder import build_from_config
from orca_ros.examples.common import integrate
from orca_ros.servo.target_trajectory import CartesianTrajectory
import pinocchio as pin
import yaml

DT = 1e-3
Q0 = np.array([0.0, -1.2, 1.6, -1.9, -1.57, 0.0])  # the UR5's working posture (issue 37)
SAFETY = 0.04
CARTESIAN = {'max_velocity': [0.25, 1.0], 'max_acceleration': [1.0, 3.0],
             'max_jerk': [5.0, 15.0]}  # the node's defaults for a Cartesian task's targets


def _ur5(example_robot_urdf, floors=True):
    urdf = example_robot_urdf('ur_description/urdf/ur5_robot.urdf')
    srdf = example_robot_urdf('ur_description/srdf/ur5.srdf')
    with open(orca.share_path('config', 'lwr_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    cfg.pop('base_frame')
    cfg['urdf_path'] = urdf
    cfg['joints'] = ['shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint', 'wrist_1_joint',
                     'wrist_2_joint', 'wrist_3_joint']
    cfg['tasks']['ee']['frame'] = 'tool0'
    cfg['tasks']['posture']['target'] = Q0.tolist()
    cfg['constraints']['names'] = cfg['constraints']['names'] + ['collision']
    cfg['constraints']['collision'] = {'type': 'collision_avoidance', 'srdf': srdf,
                                       'safety_distance': SAFETY, 'pair_samples': 0}
    setup = build_from_config(cfg)
    col = setup.controller.get_constraint('collision')
    if not floors:  # every pair's floor the safety distance: a pair inside is pushed out
        col.floor_of = lambda k, d, cycle: SAFETY
        setup.controller.compiled = False
    return setup.robot, setup.controller, urdf


def _wrist_distance(model, urdf):
    share = urdf.split('/example-robot-data/')[0]
    gm = pin.buildGeomFromUrdf(model, urdf, pin.COLLISION, package_dirs=[share])
    names = [g.name for g in gm.geometryObjects]
    a, b = names.index('wrist_1_link_0'), names.index('ee_link_0')
    gd, data = pin.GeometryData(gm), model.createData()
    objects = gm.geometryObjects

    def distance(q):
        pin.updateGeometryPlacements(model, data, gm, gd, q)
        r = coal.DistanceResult()
        coal.distance(objects[a].geometry, coal.Transform3s(gd.oMg[a]), objects[b].geometry,
                      coal.Transform3s(gd.oMg[b]), coal.DistanceRequest(), r)
        return r.min_distance

    return distance


def _run(example_robot_urdf, floors):
    robot, c, urdf = _ur5(example_robot_urdf, floors)
    distance = _wrist_distance(robot.model, urdf)
    q, v = Q0.copy(), np.zeros(6)
    robot.set_robot_state(q, v)
    hand = robot.get_frame_pose('tool0')
    target = hand.copy()
    target[:3, 3] += [0.1, 0.0, 0.0]
    servo = c.get_task('ee').servo_controller()
    servo.set_desired(hand.copy())
    c.activate_tasks_and_constraints()
    path = CartesianTrajectory(**CARTESIAN)
    path.start(0.5, hand.copy(), np.zeros(6), np.zeros(6), target)
    taus, gaps, failures, fastest = [], [], 0, 0.0
    for k in range(2500):
        t = k * DT
        robot.set_robot_state(q, v)
        if t >= 0.5:
            servo.set_desired(*path.follow(t, servo.get_current_cartesian_pose()))
        failures += not c.update(t, DT)
        taus.append(c.get_joint_torque_command())
        q, v = integrate(robot, q, v, taus[-1], DT)
        gaps.append(distance(q))
        fastest = max(fastest, np.abs(v).max())
    robot.set_robot_state(q, v)
    error = np.linalg.norm(robot.get_frame_pose('tool0')[:3, 3] - target[:3, 3])
    steps = np.abs(np.diff(np.array(taus), axis=0)).max(axis=1)
    return distance(Q0), np.array(gaps), steps, failures, fastest, error, c


def test_a_self_pair_found_inside_is_held_not_pushed_apart(example_robot_urdf):
    start, gaps, steps, failures, fastest, error, c = _run(example_robot_urdf, True)
    col = c.get_constraint('collision')
    # the pair is inside the safety distance from the start (the hulls rounded by 1 cm each)
    assert start < SAFETY + 2 * col.geometry.rounding
    print(f'start {start * 1e3:.2f} mm, least {gaps.min() * 1e3:.2f} mm, largest step '
          f'{steps.max():.2f} Nm, fastest joint {fastest:.2f} rad/s, failures {failures}, '
          f'hand {error * 1e3:.2f} mm from its target')
    assert failures == 0
    # held where found: the meshes no closer than at the start (the rows stop a closing pair
    # within one cycle's travel at the hand's speeds: < 0.1 mm)
    assert gaps.min() > start - 1e-4
    assert steps.max() <= 2.0
    assert fastest <= 1.5 + 1e-6  # the shipped velocity limit
    assert error < 1e-3


def test_the_same_start_pushed_apart_spins_the_wrist(example_robot_urdf):
    """The counterfactual: the pair's floor at the safety distance (pushed out at A)."""
    start, gaps, steps, failures, fastest, error, _ = _run(example_robot_urdf, False)
    print(f'pushed out: largest step {steps.max():.2f} Nm, fastest joint {fastest:.2f} rad/s, '
          f'failures {failures}, hand {error * 1e3:.1f} mm from its target')
    assert failures > 1000 and error > 0.1
