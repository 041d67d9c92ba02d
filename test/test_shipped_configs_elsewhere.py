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
The shipped configurations on robots they were not written for (issue 22).

A user adapts a shipped YAML to their robot by its names only: URDF, joints, frames, the posture
and stance of the robot. Everything else (gains, weights, limits, contacts, balance, the solver)
stays as shipped, built by ``build_from_config`` as the node builds it, in PyBullet:

- config/lwr_controller.yaml on the iiwa (pybullet_data) and the UR5 (example-robot-data): three
  Cartesian targets 10 cm apart, each a step, within the URDF's torque, position and velocity
  limits;
- config/quadruped_controller.yaml on Solo12 (2.5 kg) and Go1 (13 kg) of example-robot-data,
  standing in their SRDF's pose: the trunk moved 2 cm sideways and back.
"""

import copy

import numpy as np
import orca_ros as orca
from orca_ros.configuration import build_from_config
from orca_ros.examples.quadruped import state_from_sim
from orca_ros.sim import resolve_package_uris, SimServer
import pytest
from test_other_quadrupeds import _standing
import yaml

DT = 0.001
OFFSETS = ([0.1, 0.0, 0.0], [0.0, 0.1, -0.05], [-0.05, -0.1, 0.05])


def _shipped(name):
    with open(orca.share_path('config', name)) as fh:
        return yaml.safe_load(fh)['orca_controller']['ros__parameters']


def _build(cfg):
    setup = build_from_config(cfg)
    c = setup.controller
    for name, active in setup.initially_active.items():  # as the node does
        if active:
            (c.get_task(name) if name in setup.tasks else c.get_constraint(name)).activate()
    return setup


def _resolved(urdf, tmp_path):
    path = tmp_path / 'robot.urdf'
    with open(urdf) as f:
        path.write_text(resolve_package_uris(f.read(), urdf))
    return str(path)


ARMS = {  # arm: (URDF, its base link, tool frame, start posture)
    'iiwa': (None, 'lbr_iiwa_link_0', 'lbr_iiwa_link_7', [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]),
    'ur5': ('ur_description/urdf/ur5_robot.urdf', 'base_link', 'tool0',
            [0.0, -1.3, 1.5, -1.8, -1.57, 0.0]),
}


@pytest.mark.parametrize('which', sorted(ARMS))
def test_the_arm_configuration_on_another_arm(which, iiwa_urdf, example_robot_urdf, tmp_path):
    rel, base, tool, q0 = ARMS[which]
    urdf = iiwa_urdf if rel is None else _resolved(example_robot_urdf(rel), tmp_path)
    q0 = np.asarray(q0, dtype=float)
    probe = orca.RobotModel()
    probe.load_model_from_file(urdf)
    cfg = copy.deepcopy(_shipped('lwr_controller.yaml'))
    cfg.update(urdf_path=urdf, base_frame=base, joints=probe.get_joint_names())
    cfg['tasks']['ee']['frame'] = tool
    cfg['tasks']['posture']['target'] = q0.tolist()
    setup = _build(cfg)
    robot, c, ee = setup.robot, setup.controller, setup.tasks['ee']
    names = robot.get_joint_names()
    robot.set_robot_state(q0, np.zeros(q0.size))
    lo, hi = robot.get_joint_position_limits()
    vmax, tmax = robot.get_joint_velocity_limits(), robot.get_joint_torque_limits()
    start = robot.get_frame_pose(tool)
    failures, errors, over = 0, [], 0.0
    with SimServer(time_step=DT) as server:
        sim = server.insert_model_from_urdf_file(urdf, fixed_base=True)
        by_name = sim.joint_map(names)
        sim.set_model_configuration(names, q0)
        for offset in OFFSETS:
            target = start.copy()
            target[:3, 3] += offset
            ee.servo_controller().set_desired(target)
            for _ in range(2500):
                q, v = sim.get_joint_positions(by_name), sim.get_joint_velocities(by_name)
                over = max(over, float(np.max(q - hi)), float(np.max(lo - q)),
                           float(np.max(np.abs(v) - vmax)))
                robot.set_robot_state(q, v)
                failures += not c.update(server.get_time(), DT)
                tau = c.get_joint_torque_command()
                over = max(over, float(np.max(np.abs(tau) - tmax)))
                sim.set_joint_torque_command(tau, by_name)
                server.step()
            robot.set_robot_state(sim.get_joint_positions(by_name), np.zeros(q0.size))
            errors.append(np.linalg.norm(robot.get_frame_pose(tool)[:3, 3] - target[:3, 3]))
    print(f'{which}: final errors {np.round(np.array(errors) * 1e3, 4)} mm, limits exceeded by '
          f'{over:.1e}')
    assert failures == 0
    assert max(errors) < 2e-4, f'final errors {np.round(np.array(errors) * 1e3, 3)} mm'
    assert over < 1e-6, f'limits exceeded by {over:.2e}'


QUADRUPEDS = {'solo12': 'base_link', 'go1': 'trunk'}  # robot: its trunk's frame
SHIFT = np.array([0.0, 0.02, 0.0])


@pytest.mark.parametrize('which', sorted(QUADRUPEDS))
def test_the_quadruped_configuration_on_another_quadruped(which, example_robot_urdf, tmp_path):
    stand, q, urdf, feet = _standing(example_robot_urdf, which)
    urdf = _resolved(urdf, tmp_path)
    cfg = copy.deepcopy(_shipped('quadruped_controller.yaml'))
    cfg.update(urdf_path=urdf, joints=stand.get_joint_names())
    base = cfg['tasks']['base']
    base['frame'] = QUADRUPEDS[which]
    stand.set_configuration(q, np.zeros(stand.model.nv))
    home = stand.get_frame_pose(QUADRUPEDS[which])[:3, 3].copy()
    base['target_position'] = home.tolist()
    cfg['tasks']['posture']['target'] = q[7:].tolist()
    for leg, foot in zip(('FL', 'FR', 'HL', 'HR'), feet):
        cfg['constraints'][f'{leg}_contact']['frame'] = foot
    setup = _build(cfg)
    robot, c, servo = setup.robot, setup.controller, setup.tasks['base'].servo_controller()
    names = robot.get_joint_names()
    robot.set_configuration(q, np.zeros(robot.model.nv))
    failures, tilt, trunk = 0, 0.0, []
    with SimServer(time_step=DT) as server:
        sim = server.insert_model_from_urdf_file(
            urdf, position=q[:3], orientation=q[3:7], fixed_base=False
        )
        by_name = sim.joint_map(names)
        sim.set_model_configuration(names, q[7:])
        for k in range(3000):
            t = k * DT
            target = np.eye(4)
            target[:3, 3] = home + (SHIFT if 0.5 <= t < 1.75 else 0.0)
            servo.set_desired(target)
            state_from_sim(robot, sim, by_name)
            T = sim.get_world_to_base_transform()
            failures += not c.update(t, DT)
            sim.set_joint_torque_command(c.get_joint_torque_command(), by_name)
            server.step()
            tilt = max(tilt, float(np.arccos(np.clip(T[2, 2], -1.0, 1.0))))
            if k in (1499, 2999):
                trunk.append(robot.get_frame_pose(QUADRUPEDS[which])[:3, 3] - home)
    moved, back = trunk
    print(f'{which}: trunk {np.round(moved * 1e3, 2)} mm at the shift, {np.round(back * 1e3, 2)} '
          f'mm back; tilt {np.degrees(tilt):.2f} deg')
    assert failures == 0
    assert np.linalg.norm(moved - SHIFT) < 2e-3 and np.linalg.norm(back) < 2e-3
    assert tilt < np.radians(3.0)
