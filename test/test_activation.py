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
"""Activation life cycle: smooth ramps, callback order, deactivation."""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import (
    add_standard_constraints,
    make_cartesian_servo,
    make_controller,
    make_robot,
)


def _controller(urdf, ramp, weight=2.0):
    robot, _ = make_robot(urdf)
    c = make_controller(robot)
    task = c.add_task(orca.CartesianTask, 'cart')
    task.set_servo_controller(make_cartesian_servo('link_7', orca.make_transform([0.4, 0.2, 0.6])))
    task.set_weight(weight)
    task.set_ramp_duration(ramp)
    add_standard_constraints(c)
    return robot, c, task


def test_smooth_ramp_profile():
    x = np.linspace(0, 1, 1001)
    s = np.array([orca.smooth_ramp(v) for v in x])
    assert s[0] == 0.0 and s[-1] == 1.0 and np.all(np.diff(s) >= 0)
    ds = np.array([orca.math.smooth_ramp_derivative(v) for v in x])
    assert abs(ds[0]) < 1e-12 and abs(ds[-1]) < 1e-12  # C1 at both ends
    np.testing.assert_allclose(np.gradient(s, x)[1:-1], ds[1:-1], atol=1e-3)


def test_weight_ramps_up_and_down_smoothly(lwr_urdf):
    T, dt, w = 0.5, 0.001, 2.0
    robot, c, task = _controller(lwr_urdf, T, w)
    events = []
    task.on_activation_callback(lambda: events.append('activation'))
    task.on_activated_callback(lambda: events.append('activated'))
    task.on_deactivation_callback(lambda: events.append('deactivation'))
    task.on_deactivated_callback(lambda: events.append('deactivated'))
    begins, ends = [], []
    task.on_compute_begin_callback(lambda t, d: begins.append(t))
    task.on_compute_end_callback(lambda t, d: ends.append(t))
    assert task.get_state() is orca.ActivationState.INIT
    c.activate_tasks_and_constraints()
    assert task.get_state() is orca.ActivationState.ACTIVATING
    t, weights, torques = 0.0, [], []
    for k in range(int(T / dt) + 200):
        assert c.update(t, dt)
        weights.append(task.get_effective_weight())
        torques.append(c.get_joint_torque_command())
        if k == 0:
            assert weights[0] == 0.0
        t += dt
    weights = np.array(weights)
    i_T = int(round(T / dt))
    assert abs(weights[i_T] - w) < 1e-12 and np.all(weights[i_T:] == w)
    assert task.is_activated()
    # continuous derivative: the slope changes by a bounded amount per step, and is ~0 at both ends
    slope = np.diff(weights) / dt
    assert abs(slope[0]) < 1e-3 and abs(slope[i_T - 1]) < 1e-3
    assert np.max(np.abs(np.diff(slope))) < 30 * w / T**2 * dt * 1.01
    c.deactivate_tasks_and_constraints()
    down = []
    while not c.tasks_and_constraints_deactivated():
        assert c.update(t, dt)
        down.append(task.get_effective_weight())
        t += dt
    down = np.array(down)
    assert abs(len(down) - T / dt) <= 1  # deactivated after the ramp, not before
    assert down[0] == w and down[-1] == 0.0 and np.all(np.diff(down) <= 0)
    assert np.max(np.abs(np.diff(np.diff(down) / dt))) < 30 * w / T**2 * dt * 1.01
    assert events == ['activation', 'activated', 'deactivation', 'deactivated']
    assert len(begins) == len(ends) == len(weights) + len(down) and begins == ends
    # once deactivated, nothing more is called
    c.update(t, dt)
    assert len(begins) == len(weights) + len(down)


def test_deactivation_during_activation_reverses_without_jump(lwr_urdf):
    T, dt = 0.4, 0.001
    robot, c, task = _controller(lwr_urdf, T, 1.0)
    c.activate_tasks_and_constraints()
    t, weights = 0.0, []
    for _ in range(150):
        c.update(t, dt)
        weights.append(task.get_effective_weight())
        t += dt
    c.deactivate_tasks_and_constraints()
    while not c.tasks_and_constraints_deactivated():
        c.update(t, dt)
        weights.append(task.get_effective_weight())
        t += dt
    weights = np.array(weights)
    assert (
        np.max(np.abs(np.diff(weights))) < 2.0 * dt / T
    )  # no step: bounded by the ramp's max slope
    assert weights[-1] == 0.0
    assert len(weights) < 150 + 160  # it goes back from where it was, so faster than a full ramp


def test_activation_holds_current_pose_when_no_target(lwr_urdf):
    robot, _ = make_robot(lwr_urdf)
    q = np.array([0.2, 0.5, 0.0, -1.0, 0.0, 0.6, 0.0])
    robot.set_robot_state(q, np.zeros(7))
    c = make_controller(robot)
    task = c.add_task(orca.CartesianTask, 'cart')
    task.set_control_frame('link_7')
    task.servo_controller().pid().set_proportional_gain(100.0)
    task.servo_controller().pid().set_derivative_gain(20.0)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 0.001)
    pose_ref = task.servo_controller().get_desired()[0]
    np.testing.assert_allclose(pose_ref, robot.get_frame_pose('link_7'), atol=1e-12)
    # holding a pose at rest needs exactly zero acceleration (pure gravity compensation)
    np.testing.assert_allclose(c.get_joint_acceleration_command(), 0.0, atol=1e-8)
