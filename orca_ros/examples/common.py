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
Shared set-up of the examples.

Argument parsing, the arm model, the usual constraints, a simulator step.
"""

from __future__ import annotations

import argparse

import numpy as np

from .arm import add_frame_args, posture
from .. import (
    CartesianAccelerationPID,
    CartesianTask,
    Controller,
    default_urdf_path,
    JointAccelerationTask,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
    Logger,
    QPSolver,
    ResolutionStrategy,
    RobotModel,
    RobotState,
)


def parse_args(description: str, argv=None, extra=None):
    """
    Parse the examples' command line.

    ``example [urdf] [-l level] [--solver daqp|proxqp|osqp] [--time-budget S] + extra options``.
    """
    rest = Logger.parse_argv(argv)
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument(
        'urdf', nargs='?', default=None, help='robot URDF (default: the shipped lwr.urdf)'
    )
    parser.add_argument('--solver', default='daqp', choices=[s.value for s in QPSolver])
    parser.add_argument(
        '--time-budget',
        type=float,
        default=None,
        help='seconds each control cycle may spend solving (default: one control period)',
    )
    add_frame_args(parser)
    if extra is not None:
        extra(parser)
    args = parser.parse_args(rest)
    if args.urdf is None:
        args.urdf = default_urdf_path()
    return args


def make_robot(urdf: str, base: str | None = None):
    """
    Arm model in its base frame, with gravity, at rest; returns (robot, state).

    ``base``: the base frame (default: the URDF's root link, the lwr's ``base_link``). The posture
    is q = 0 clipped into the joint limits (:func:`.arm.posture`; q = 0 on the lwr).
    """
    robot = RobotModel()
    robot.load_model_from_file(urdf)
    robot.set_base_frame(base or robot.get_base_frame())
    robot.set_gravity(np.array([0.0, 0.0, -9.81]))
    state = RobotState(robot.get_nr_of_degrees_of_freedom())
    state.set_zero()
    state.joint_pos = posture(robot, state.joint_pos)
    robot.set_robot_state(state.joint_pos, state.joint_vel)
    return robot, state


def make_controller(robot, solver: str = 'daqp') -> Controller:
    return Controller(
        'controller', robot, ResolutionStrategy.ONE_LEVEL_WEIGHTED, QPSolver.from_string(solver)
    )


def make_cartesian_servo(frame: str = 'link_7', target=None) -> CartesianAccelerationPID:
    """Make the reference examples' servo: P = 1000 (position) / 10 (orientation), D = 100 / 1."""
    servo = CartesianAccelerationPID('servo_controller')
    servo.pid().set_proportional_gain([1000, 1000, 1000, 10, 10, 10])
    servo.pid().set_derivative_gain([100, 100, 100, 1, 1, 1])
    servo.set_control_frame(frame)
    if target is not None:
        servo.set_desired(target, np.zeros(6), np.zeros(6))
    return servo


def add_standard_constraints(
    controller: Controller, torque_max: float = 200.0, velocity_max: float = 2.0
):
    """
    Torque limits +-200 Nm (clipped to the URDF's efforts).

    URDF position limits, velocity limits.
    """
    n = controller.robot.get_nr_of_degrees_of_freedom()
    trq = controller.add_constraint(JointTorqueLimitConstraint, 'JointTorqueLimit')
    urdf_effort = controller.robot.get_joint_torque_limits()
    tmax = np.minimum(np.full(n, torque_max), np.where(urdf_effort > 0, urdf_effort, np.inf))
    trq.set_limits(-tmax, tmax)
    pos = controller.add_constraint(JointPositionLimitConstraint, 'JointPositionLimit')
    vel = controller.add_constraint(JointVelocityLimitConstraint, 'JointVelocityLimit')
    vmax = np.minimum(np.full(n, velocity_max), controller.robot.get_joint_velocity_limits())
    vel.set_limits(-vmax, vmax)
    return trq, pos, vel


#: the bent posture the conflicting stack starts from (lwr.urdf)
STACK_Q0 = np.array([0.3, 0.7, -0.2, -1.1, 0.4, 0.6, 0.1])
#: the Panda's (example-robot-data, fingers included) for the same stack
STACK_Q0_PANDA = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.6, 0.8, 0.02, 0.02])
#: the conflicting stack on other arms: {arm: (end effector frame, elbow frame, start posture)}
#: (lwr: the package's; iiwa: pybullet_data's; panda: example-robot-data's)
STACK_ARMS = {
    'lwr': ('link_7', 'link_4', STACK_Q0),
    'iiwa': ('lbr_iiwa_link_7', 'lbr_iiwa_link_4', STACK_Q0),
    'panda': ('panda_link8', 'panda_link4', STACK_Q0_PANDA),
}


def add_conflicting_stack(
    controller: Controller, n_tasks: int = 3, frames=('link_7', 'link_4'), posture=None
) -> dict:
    """
    Add the arm's 3-level stack whose elbow task pulls against the end effector.

    Levels: end-effector position (level 0, weight 1), elbow position pulling elsewhere (level 1,
    weight 10), joint posture towards ``posture`` (None: zero; level 2); the first ``n_tasks`` of
    them, targets offset from the current poses. ``frames``: the end effector's and the elbow's
    (lwr.urdf's by default). Returns the tasks by name.
    """
    robot = controller.robot
    specs = [
        ('ee', frames[0], [0.05, -0.08, 0.04], 1.0),
        ('elbow', frames[1], [-0.2, 0.3, -0.1], 10.0),
    ]
    tasks = {}
    for level, (name, frame, offset, weight) in enumerate(specs[:n_tasks]):
        t = controller.add_task(CartesianTask, name, level=level)
        t.set_control_frame(frame)
        t.servo_controller().pid().set_proportional_gain(100.0)
        t.servo_controller().pid().set_derivative_gain(20.0)
        target = robot.get_frame_pose(frame)
        target[:3, 3] += offset
        t.servo_controller().set_desired(target)
        t.set_selection_vector([1, 1, 1, 0, 0, 0])
        t.set_weight(weight)
        tasks[name] = t
    if n_tasks >= 3:
        post = controller.add_task(JointAccelerationTask, 'posture', level=2)
        post.pid().set_proportional_gain(25.0)
        post.pid().set_derivative_gain(10.0)
        n = robot.get_nr_of_degrees_of_freedom()
        post.set_desired(np.zeros(n) if posture is None else np.asarray(posture, dtype=float))
        tasks['posture'] = post
    return tasks


def integrate(robot, q: np.ndarray, v: np.ndarray, tau: np.ndarray, dt: float):
    """
    Integrate one step of the rigid-body dynamics under torques tau.

    As the reference's second example.
    """
    acc = np.linalg.solve(
        robot.get_mass_matrix(), tau - robot.get_joint_gravity_and_coriolis_torques()
    )
    q_new = q + v * dt + 0.5 * acc * dt * dt
    v_new = v + acc * dt
    return q_new, v_new
