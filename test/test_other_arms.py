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
Arms this project was not tuned on, in PyBullet, with default limits (fixed base).

UR5, xArm7 and the Kinova Jaco2 (three *continuous* joints: cos/sin pairs in Pinocchio's
configuration, no position limit) from example-robot-data reach three Cartesian targets 10 cm
apart in turn under the URDF's torque, position and velocity limits.
"""

import numpy as np
import orca_ros as orca
from orca_ros.sim import resolve_package_uris, SimServer
import pytest

DT = 0.001
# arm: (URDF, tool frame, start posture)
ARMS = {
    'ur5': ('ur_description/urdf/ur5_robot.urdf', 'tool0', [0.0, -1.3, 1.5, -1.8, -1.57, 0.0]),
    'xarm7': ('xarm_description/urdf/xarm7.urdf', 'link_eef', [0.3] * 7),
    'kinova': (
        'kinova_description/robots/kinova.urdf',
        'j2s6s200_end_effector',
        [0.0, 2.9, 1.3, -2.07, 1.4, 0.0],
    ),
}
OFFSETS = ([0.1, 0.0, 0.0], [0.0, 0.1, -0.05], [-0.05, -0.1, 0.05])


@pytest.mark.parametrize('which', sorted(ARMS))
def test_an_arm_reaches_targets_within_its_limits(example_robot_urdf, tmp_path, which):
    rel, tool, q0 = ARMS[which]
    urdf = example_robot_urdf(rel)
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    names = robot.get_joint_names()
    q0 = np.asarray(q0, dtype=float)
    robot.set_gravity(np.array([0.0, 0.0, -9.81]))
    robot.set_robot_state(q0, np.zeros(q0.size))
    c = orca.Controller(which, robot)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame(tool)
    ee.servo_controller().pid().set_proportional_gain(100.0)
    ee.servo_controller().pid().set_derivative_gain(20.0)
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(1e-3)
    posture.set_desired(q0)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position_limit')
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity_limit')
    c.activate_tasks_and_constraints()
    lo, hi = robot.get_joint_position_limits()
    vmax, tmax = robot.get_joint_velocity_limits(), robot.get_joint_torque_limits()
    if which == 'kinova':  # its continuous joints have no position limit
        assert np.sum(np.isinf(lo)) == 3 and np.sum(np.isinf(hi)) == 3
    start = robot.get_frame_pose(tool)
    path = tmp_path / f'{which}.urdf'
    with open(urdf) as f:
        path.write_text(resolve_package_uris(f.read(), urdf))
    failures, errors, worst = 0, [], 0.0
    with SimServer(time_step=DT) as server:
        sim = server.insert_model_from_urdf_file(str(path), fixed_base=True)
        by_name = sim.joint_map(names)
        sim.set_model_configuration(names, q0)
        for offset in OFFSETS:
            target = start.copy()
            target[:3, 3] += offset
            ee.servo_controller().set_desired(target)
            for _ in range(2000):
                q, v = sim.get_joint_positions(by_name), sim.get_joint_velocities(by_name)
                worst = max(worst, float(np.max(q - hi)), float(np.max(lo - q)))
                worst = max(worst, float(np.max(np.abs(v) - vmax)))
                robot.set_robot_state(q, v)
                failures += not c.update(server.get_time(), DT)
                tau = c.get_joint_torque_command()
                assert np.all(np.abs(tau) <= tmax + 1e-9)
                sim.set_joint_torque_command(tau, by_name)
                server.step()
            robot.set_robot_state(sim.get_joint_positions(by_name), np.zeros(q0.size))
            pose = robot.get_frame_pose(tool)
            errors.append(np.linalg.norm(pose[:3, 3] - target[:3, 3]))
    assert failures == 0
    assert max(errors) < 2e-4, f'final errors {np.round(np.array(errors) * 1e3, 3)} mm'
    assert worst < 1e-6, f'limits exceeded by {worst:.2e}'  # PyBullet integrates semi-implicitly
