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
Strict levels without torque steps: temporal damping of the levels below the first.

The 3-level arm stack (end effector level 0, an elbow task pulling elsewhere level 1, posture
level 2) in closed loop for 2 s: undamped, the elbow level hops between vertices of the bounds left
to it while joints ride their velocity limits (4.3 Nm steps in one 1 ms cycle); damped, every step
after the switch-on stays below 2 Nm, and the end effector's rows keep the level-0 solution
exactly.
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_standard_constraints, integrate

Q0 = np.array([0.3, 0.7, -0.2, -1.1, 0.4, 0.6, 0.1])


def _stack(robot, damping):
    c = orca.Controller('c', robot, orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED)
    specs = [
        ('ee', 'link_7', [0.05, -0.08, 0.04], 1.0),
        ('elbow', 'link_4', [-0.2, 0.3, -0.1], 10.0),
    ]
    tasks = {}
    for level, (name, frame, offset, weight) in enumerate(specs):
        t = c.add_task(orca.CartesianTask, name, level=level)
        t.set_control_frame(frame)
        t.servo_controller().pid().set_proportional_gain(100.0)
        t.servo_controller().pid().set_derivative_gain(20.0)
        target = robot.get_frame_pose(frame)
        target[:3, 3] += offset
        t.servo_controller().set_desired(target)
        t.set_selection_vector([1, 1, 1, 0, 0, 0])
        t.set_weight(weight)
        tasks[name] = t
    post = c.add_task(orca.JointAccelerationTask, 'posture', level=2)
    post.pid().set_proportional_gain(25.0)
    post.pid().set_derivative_gain(10.0)
    post.set_desired(np.zeros(7))
    add_standard_constraints(c)
    for o in c.get_tasks():
        o.set_ramp_duration(0.0)  # switched on at once: the steps judged are those after 20 ms
    c.set_lower_level_damping(damping)
    c.activate_tasks_and_constraints()
    return c, tasks


def _run(damping, seconds=2.0):
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(Q0, np.zeros(7))
    c, tasks = _stack(robot, damping)
    q, v, dt = Q0.copy(), np.zeros(7), 0.001
    taus, lock = [], 0.0
    for k in range(int(round(seconds / dt))):
        robot.set_robot_state(q, v)
        assert c.update(k * dt, dt), c.get_return_code()
        E = tasks['ee'].get_E()[:3]
        x0 = c.get_problem_at_level(0).x
        x = c.get_problem_at_level(2).x  # the final solution
        if k * dt > 0.02:
            lock = max(lock, float(np.abs(E @ (x - x0)).max()))
        taus.append(c.get_joint_torque_command())
        q, v = integrate(robot, q, v, taus[-1], dt)
    # the switch-on (tasks at full weight from the first cycle) is not what is judged here
    steps = np.abs(np.diff(np.array(taus), axis=0)).max(axis=1)[20:]
    err = np.linalg.norm(tasks['ee'].servo_controller().get_cartesian_pose_error()[:3])
    return steps, lock, err


def test_damped_lower_levels_do_not_step_the_torques():
    steps, lock, err = _run(damping=100.0)
    assert steps.max() <= 2.0, f'{steps.max():.2f} Nm in one cycle'
    assert lock <= 1e-8  # the levels below never touch the end effector's accelerations
    assert err < 1e-4


def test_undamped_lower_levels_step():
    steps, lock, _ = _run(damping=0.0)
    assert steps.max() > 3.0  # what the damping removes
    assert lock <= 1e-8
