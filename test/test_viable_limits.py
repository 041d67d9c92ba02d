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
Joint position limits viable in discrete time: no excursion, on revolute and prismatic joints.

Two arms driven closed loop through 100 random reachable targets each, with the forward dynamics
integrated as the controller predicts it (q' = q + dt v + dt^2/2 a, v' = v + dt a): the 7-DoF arm
of ``urdf/lwr.urdf`` and the Franka Panda of ``pybullet_data`` with its two prismatic fingers.
Stiff gains and posture targets drawn over the whole URDF range, while the constraint's limits are
15 % tighter on each side, drive joints into their limits over and over. Positions and velocities
must stay within their limits to 1e-9 and torques within theirs, with no failed cycle.
"""

import os

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import integrate
import pybullet_data
import pytest

PANDA = os.path.join(pybullet_data.getDataPath(), 'franka_panda', 'panda.urdf')


def _arm(urdf, frame):
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    n = robot.get_nr_of_degrees_of_freedom()
    c = orca.Controller(
        'arm', robot, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, orca.QPSolver.DAQP
    )
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame(frame)
    pid = ee.servo_controller().pid()
    pid.set_proportional_gain(np.r_[np.full(3, 900.0), np.full(3, 400.0)])
    pid.set_derivative_gain(np.r_[np.full(3, 60.0), np.full(3, 40.0)])
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(0.1)
    posture.pid().set_proportional_gain(np.full(n, 400.0))
    posture.pid().set_derivative_gain(np.full(n, 40.0))
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque')
    pos = c.add_constraint(orca.JointPositionLimitConstraint, 'position')
    lo, hi = robot.get_joint_position_limits()
    margin = 0.15 * (hi - lo)
    pos.set_limits(lo + margin, hi - margin)
    vel = c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity')
    c.activate_tasks_and_constraints()
    return robot, c, ee, posture, pos, vel


@pytest.mark.parametrize('urdf, frame', [('lwr', 'link_7'), ('panda', 'panda_grasptarget')])
def test_random_targets_never_cross_a_limit(urdf, frame, lwr_urdf):
    path = lwr_urdf if urdf == 'lwr' else PANDA
    robot, c, ee, posture, pos, vel = _arm(path, frame)
    rng = np.random.default_rng(7)
    lo, hi = pos.get_limits()
    vlo, vhi = vel.get_limits()
    tau_max = robot.get_joint_torque_limits()
    urdf_lo, urdf_hi = robot.get_joint_position_limits()
    n = robot.get_nr_of_degrees_of_freedom()
    q, v = 0.5 * (lo + hi), np.zeros(n)
    probe = orca.RobotModel()
    probe.load_model_from_file(path)
    dt, t = 1e-3, 0.0
    worst_q = worst_v = worst_tau = 0.0
    at_limit = failures = 0
    for _ in range(100):
        q_goal = rng.uniform(urdf_lo, urdf_hi)  # reachable by the robot, often not within the
        probe.set_robot_state(q_goal, np.zeros(n))  # constraint's tighter limits
        ee.servo_controller().set_desired(probe.get_frame_pose(frame))
        posture.set_desired(q_goal)
        for _ in range(300):
            robot.set_robot_state(q, v)
            if not c.update(t, dt):
                failures += 1
                break
            tau = c.get_joint_torque_command()
            worst_tau = max(worst_tau, float(np.max(np.abs(tau) - tau_max)))
            q, v = integrate(robot, q, v, tau, dt)
            t += dt
            worst_q = max(worst_q, float(np.max(np.maximum(q - hi, lo - q))))
            worst_v = max(worst_v, float(np.max(np.maximum(v - vhi, vlo - v))))
            at_limit += bool(np.any(np.minimum(hi - q, q - lo) < 1e-3 * (hi - lo)))
    assert failures == 0
    assert worst_q <= 1e-9, f'position excursion {worst_q:.3g}'
    assert worst_v <= 1e-9, f'velocity excursion {worst_v:.3g}'
    assert worst_tau <= 1e-6, f'torque beyond its limit by {worst_tau:.3g}'
    assert at_limit > 1000, f'only {at_limit} cycles near a limit: the test does not exercise them'
