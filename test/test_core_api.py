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
Package-level behaviour.

No ROS import in the core, the public API, maths helpers, servos, logger.
"""

import subprocess
import sys

import numpy as np
import orca_ros as orca
import pinocchio as pin
import pytest


def test_import_does_not_pull_rclpy():
    code = "import sys, orca_ros; import orca_ros.examples.common; print('rclpy' in sys.modules)"
    out = subprocess.run(
        [sys.executable, '-c', code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == 'False'


def test_public_api_at_top_level():
    for name in [
        'RobotModel',
        'RobotState',
        'Controller',
        'CartesianTask',
        'JointAccelerationTask',
        'JointTorqueTask',
        'JointTorqueLimitConstraint',
        'JointPositionLimitConstraint',
        'JointVelocityLimitConstraint',
        'JointAccelerationLimitConstraint',
        'CartesianAccelerationPID',
        'PIDController',
        'QPSolver',
        'ResolutionStrategy',
        'Logger',
        'quat_from_rpy',
        'quat_from_kuka_convention',
    ]:
        assert hasattr(orca, name), name


def test_quaternion_conventions():
    R = orca.quat_from_rpy(0.3, -0.2, 1.1).toRotationMatrix()
    np.testing.assert_allclose(R, pin.rpy.rpyToMatrix(0.3, -0.2, 1.1), atol=1e-12)
    # KUKA A, B, C = rotations about z, y', x'' = RPY with roll C, pitch B, yaw A
    np.testing.assert_allclose(
        orca.quat_from_kuka_convention(1.1, -0.2, 0.3).toRotationMatrix(), R, atol=1e-12
    )
    np.testing.assert_allclose(
        orca.quat_from_rpy(np.pi, 0, 0).toRotationMatrix(), np.diag([1, -1, -1]), atol=1e-12
    )


def test_pose_error_is_log_map():
    Tc = orca.make_transform([0.1, 0.2, 0.3], orca.rotation_from_rpy(0.1, 0.2, 0.3))
    w = np.array([0.2, -0.1, 0.4])
    Td = orca.make_transform([0.0, 0.5, 0.3], pin.exp3(w) @ Tc[:3, :3])
    e = orca.pose_error(Td, Tc)
    np.testing.assert_allclose(e[:3], [-0.1, 0.3, 0.0], atol=1e-12)
    np.testing.assert_allclose(e[3:], w, atol=1e-12)


def test_pid_controller_gains_and_windup():
    pid = orca.PIDController(2)
    pid.set_proportional_gain([2.0, 3.0])
    pid.set_derivative_gain(0.5)
    pid.set_integral_gain([1.0, 0.0])
    pid.set_windup_limit(0.25)
    out = None
    for _ in range(100):
        out = pid.compute_command(np.array([1.0, 1.0]), np.array([0.0, 2.0]), 0.01)
    # integral of e over 1 s is 1.0, clamped to 0.25 on axis 0; axis 1 has no integral action
    np.testing.assert_allclose(out, [2.0 + 0.25, 3.0 + 1.0])
    with pytest.raises(ValueError, match='proportional gain'):
        pid.set_proportional_gain([1, 2, 3])


def test_cartesian_servo_rejects_bad_targets(lwr_urdf):
    servo = orca.CartesianAccelerationPID()
    with pytest.raises(ValueError, match='4x4'):
        servo.set_desired(np.eye(3))
    bad = np.eye(4)
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match='finite'):
        servo.set_desired(bad)
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    servo.set_robot_model(robot)
    with pytest.raises(ValueError, match="unknown frame 'tool0'"):
        servo.set_control_frame('tool0')


def test_controller_configuration_errors(lwr_urdf):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    c = orca.Controller('c', robot, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, orca.QPSolver.OSQP)
    c.add_task(orca.CartesianTask, 't')
    with pytest.raises(ValueError, match='already exists'):
        c.add_task(orca.JointAccelerationTask('t'))
    with pytest.raises(KeyError, match="no task named 'x'"):
        c.get_task('x')
    with pytest.raises(ValueError, match="unknown QP solver 'qpoases'"):
        orca.Controller('c', robot, 'one_level_weighted', 'qpoases')
    with pytest.raises(RuntimeError, match='set_robot_state'):
        c.update(0.0, 0.001)
    with pytest.raises(ValueError, match='selection vector needs 6'):
        c.get_task('t').set_selection_vector([1, 1, 1])


def test_selection_vector_ignores_orientation(lwr_urdf):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    robot.set_robot_state(np.array([0.1, 0.6, 0.0, -1.0, 0.0, 0.5, 0.0]), np.zeros(7))
    c = orca.Controller('c', robot)
    task = c.add_task(orca.CartesianTask, 't')
    task.set_control_frame('link_7')
    task.servo_controller().pid().set_proportional_gain(100.0)
    T = robot.get_frame_pose('link_7')
    T[:3, :3] = orca.rotation_from_rpy(0.5, 0.0, 0.0) @ T[:3, :3]  # only an orientation change
    task.servo_controller().set_desired(T)
    task.set_selection_vector([1, 1, 1, 0, 0, 0])
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 0.001)
    np.testing.assert_allclose(c.get_joint_acceleration_command(), 0.0, atol=1e-8)


def test_logger_levels_from_argv():
    rest = orca.Logger.parse_argv(['robot.urdf', '-l', 'debug', '--other'])
    assert rest == ['robot.urdf', '--other']
    assert orca.Logger.get_level() == 10
    orca.Logger.parse_argv(['--log_level=warning'])
    assert orca.Logger.get_level() == 30
    with pytest.raises(ValueError, match="unknown log level 'loud'"):
        orca.Logger.parse_argv(['-l', 'loud'])
    orca.Logger.set_level('info')
