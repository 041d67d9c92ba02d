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
``diagnose()`` names what conflicts.

A constraint keeping a task from its target, or the constraints that together make a problem
infeasible.

Three constructed conflicts (torque limit vs an end-effector demand, joint limit vs posture,
friction cone vs wrench task) and one infeasible problem (torques and accelerations both nearly
zero on an arm held against gravity).
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples import quadruped as quad
from orca_ros.optim.diagnosis import diagnose

Q0 = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0])


def _arm():
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(Q0, np.zeros(7))
    return robot, orca.Controller('c', robot)


def _pairs(d):
    return {(t, c) for t, c, _ in d.blocked_tasks}


def test_torque_limit_holds_back_the_end_effector():
    robot, c = _arm()
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('link_7')
    T = robot.get_frame_pose('link_7')
    T[:3, 3] += [0.3, 0.0, 0.0]
    ee.servo_controller().set_desired(T)
    ee.servo_controller().pid().set_proportional_gain(np.full(6, 100.0))
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(1e-4)
    posture.set_desired(Q0)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit').set_limits(
        np.full(7, -20.0), np.full(7, 20.0)
    )
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity_limit')
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 1e-3)
    d = diagnose(c)
    assert d.feasible and ('ee', 'torque_limit') in _pairs(d), d.text()
    assert all(con != 'velocity_limit' for _, con, _ in d.blocked_tasks)
    assert "task 'ee' held back by constraint 'torque_limit'" in d.text()


def test_joint_limit_holds_back_the_posture():
    robot, c = _arm()
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.pid().set_proportional_gain(np.full(7, 25.0))
    posture.set_desired(Q0 + [0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0])
    limit = c.add_constraint(orca.JointPositionLimitConstraint, 'position_limit')
    lo, hi = limit.get_limits()
    hi[3] = Q0[3]  # joint 3 sits at its upper limit; the posture pulls it further
    limit.set_limits(lo, hi)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 1e-3)
    d = diagnose(c)
    assert _pairs(d) == {('posture', 'position_limit')}, d.text()


def test_friction_cone_holds_back_a_wrench_task():
    robot = quad.make_robot()
    qc = quad.QuadrupedController(robot, 'daqp')
    c = qc.controller
    for o in c.get_tasks() + c.get_constraints():
        o.set_ramp_duration(0.0)
    push = c.add_task(orca.WrenchTask, 'push')
    push.set_contact(qc.contacts['FL'])
    push.set_weight(1e-2)
    push.set_desired([100.0, 0.0, 30.0, 0.0, 0.0, 0.0])  # sideways 100 N on ~37 N of load
    c.activate_tasks_and_constraints()
    qc.set_base_target(np.array([0.0, 0.0, quad.STAND_HEIGHT]))
    assert qc.update(0.0, 1e-3)
    d = diagnose(c)
    assert ('push', 'FL_contact') in _pairs(d), d.text()


def test_infeasible_problem_names_the_conflicting_constraints():
    robot, c = _arm()
    c.add_task(orca.JointAccelerationTask, 'posture').set_desired(Q0)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit').set_limits(-0.1, 0.1)
    acc = c.add_constraint(orca.JointAccelerationLimitConstraint, 'acceleration_limit')
    acc.set_limits(np.full(7, -1e-3), np.full(7, 1e-3))
    c.activate_tasks_and_constraints()
    assert not c.update(0.0, 1e-3)
    d = c.diagnose()
    assert not d.feasible
    assert set(d.conflicting_constraints) == {'torque_limit', 'acceleration_limit'}, d.text()
    assert d.text() == 'infeasible: conflicting constraints torque_limit, acceleration_limit'
