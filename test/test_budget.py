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
The shipped solve budget: one control period (1 ms) of wall-clock time per cycle.

The suite gives every controller a 10 s budget (conftest: tests judging physics must not depend on
the machine's load); every test here runs with the shipped one (``real_time_budget``). The budget
is turned into an iteration cap per solve (``QPBackend.iteration_cap``): the time left before the
cycle's deadline over the measured cost of an iteration, never fewer than the solver's
``min_iterations``.

What a shared machine lets these tests claim: a preempted cycle starts its solve late and gets
only ``min_iterations``, so a busy machine may cost a hard cycle (the landing of a push) its
solution. The tests count the failed cycles whose update still ended within the budget (the
budget, not the machine, cut them: 0 is the claim) and judge the physics (the robot stands); they
never demand wall time. The other solvers under the shipped budget: see
test_contact_velocity_feedback.py (they are tested there with the offline budget only).
"""

from types import SimpleNamespace

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_standard_constraints, integrate
from orca_ros.examples.quadruped import STAND_HEIGHT
from orca_ros.optim.solvers import base
import pytest

pytestmark = pytest.mark.real_time_budget


def _backend(fixed, per, max_iterations=1000, min_iterations=10):
    b = base.QPBackend(2, 0, 0)
    b.timing[:] = fixed, per
    b.max_iterations, b.min_iterations = max_iterations, min_iterations
    return b


@pytest.fixture
def clock(monkeypatch):
    """Freeze the clock the budget reads at ``clock.now`` [s]."""
    c = SimpleNamespace(now=100.0)
    monkeypatch.setattr(base, 'time', SimpleNamespace(perf_counter=lambda: c.now))
    return c


def test_iteration_cap_turns_the_time_left_into_iterations(clock):
    # 10 ms left: 40 % of it (4 ms) for the solve, 1 ms of it the fixed cost, then 27.3
    # iterations of 0.11 ms after the first
    b = _backend(fixed=1e-3, per=1.1e-4)
    b.deadline = clock.now + 10e-3
    assert b.iteration_cap() == 28
    clock.now += 5e-3  # half of it gone: 2 ms for the solve, 9.1 iterations after the first
    assert b.iteration_cap() == 10
    # no per-iteration estimate yet (only solves of 1-2 iterations): the fixed cost stands for it
    b = _backend(fixed=1.1e-4, per=0.0)
    b.deadline = clock.now + 10e-3
    assert b.iteration_cap() == 1 + 35


def test_iteration_cap_is_bounded_by_min_and_max_iterations(clock):
    b = _backend(fixed=1e-3, per=1e-4, max_iterations=500, min_iterations=10)
    b.deadline = clock.now - 1.0  # a cycle already late: the floor (being late alone never fails)
    assert b.iteration_cap() == 10
    b.deadline = clock.now + 10.0  # 40 000 iterations' worth: the solver's own cap
    assert b.iteration_cap() == 500
    b.deadline = None  # a configuration cycle: no deadline
    assert b.iteration_cap() == 500
    b = _backend(fixed=0.0, per=0.0, max_iterations=500)  # no solve timed yet
    b.deadline = clock.now + 1e-6
    assert b.iteration_cap() == 500


def test_a_preempted_solve_barely_moves_the_timing_model():
    b = _backend(fixed=0.0, per=0.0)
    b.record(1e-4, 1)  # the first solve sets the fixed cost
    b.record(1e-4 + 9 * 1e-5, 10)  # ... a longer one the cost per iteration
    assert tuple(b.timing) == pytest.approx((1e-4, 1e-5))
    b.record(1.0, 1)  # preempted for a second: the estimate rises at most to 1.6x
    assert b.timing[0] == pytest.approx(1.6e-4)
    for _ in range(100):  # and falls back slowly on ordinary solves
        b.record(1e-4, 2)
    assert b.timing[0] == pytest.approx(1e-4, rel=0.01)


def test_the_controller_gives_each_cycle_one_period(lwr_urdf, monkeypatch):
    """The shipped budget reaches the solver: each solve's deadline is one period after start."""
    assert orca.Controller.default_time_budget is None  # the marker restored the shipped value
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    robot.set_robot_state(np.array([0.3, 0.7, -0.2, -1.1, 0.4, 0.6, 0.1]), np.zeros(7))
    c = orca.Controller('c', robot, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, 'daqp')
    assert c.get_solver_budget() == (None, None)
    add_standard_constraints(c)
    c.activate_tasks_and_constraints()
    deadlines = []
    cap = base.QPBackend.iteration_cap

    def spy(backend):
        deadlines.append(backend.deadline)
        return cap(backend)

    monkeypatch.setattr(base.QPBackend, 'iteration_cap', spy)
    assert c.update(0.0, 2e-3)  # a configuration cycle: not time-bounded
    assert deadlines and set(deadlines) == {None}
    fused = getattr(c.compiled_cycle, 'fused', None)
    if fused is not None:  # the one-call cycle's kernel caps its solve itself (fused_step.py)
        step = fused.kernel
        fused.kernel = lambda *a: deadlines.append(a[2]) or step(*a)  # (frame, dt, deadline, ..)
    for dt in (1e-3, 5e-3):
        deadlines.clear()
        start = base.time.perf_counter()
        assert c.update(0.0, dt)
        end = base.time.perf_counter()
        assert deadlines and all(start + dt <= d <= end + dt for d in deadlines)


def _track_circle(lwr_urdf, solver, budget, cycles=1000):
    """Drive the arm's end effector on a 0.1 m circle at 1 Hz; return its torques, failures."""
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    q, v = np.array([0.3, 0.7, -0.2, -1.1, 0.4, 0.6, 0.1]), np.zeros(7)
    robot.set_robot_state(q, v)
    c = orca.Controller('c', robot, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver)
    c.set_solver_budget(time_budget=budget)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('link_7')
    ee.servo_controller().pid().set_proportional_gain(400.0)
    ee.servo_controller().pid().set_derivative_gain(40.0)
    post = c.add_task(orca.JointAccelerationTask, 'posture')
    post.set_weight(1e-3)
    post.pid().set_proportional_gain(25.0)
    post.pid().set_derivative_gain(10.0)
    post.set_desired(q.copy())
    add_standard_constraints(c)
    c.activate_tasks_and_constraints()
    T0, dt, w, r = robot.get_frame_pose('link_7'), 1e-3, 2 * np.pi, 0.1
    torques, failures = [], 0
    for k in range(cycles):
        s, co = np.sin(w * k * dt), np.cos(w * k * dt)
        T = T0.copy()
        T[:3, 3] += [r * s, r * (1 - co), 0.0]
        vel, acc = np.zeros(6), np.zeros(6)
        vel[:3], acc[:3] = [r * w * co, r * w * s, 0.0], [-r * w * w * s, r * w * w * co, 0.0]
        ee.servo_controller().set_desired(T, vel, acc)
        failures += not c.update(k * dt, dt)
        torques.append(c.get_joint_torque_command().copy())
        q, v = integrate(robot, q, v, torques[-1], dt)
        robot.set_robot_state(q, v)
    return np.array(torques), failures


@pytest.mark.parametrize('solver', ['daqp', 'proxqp', 'osqp'])
def test_late_cycles_alone_never_fail(lwr_urdf, solver):
    """
    Every solve started past its deadline (a 1 ns budget): each gets its solver's minimum.

    Warm-started tracking needs no more: not one cycle fails, and the torques are those of the
    10 s budget to the last bit (the outcome of a solve does not depend on the machine's load).
    """
    late, late_failures = _track_circle(lwr_urdf, solver, 1e-9)
    offline, offline_failures = _track_circle(lwr_urdf, solver, 10.0)
    assert late_failures == 0 and offline_failures == 0
    np.testing.assert_array_equal(late, offline)
    assert np.isfinite(late).all()


@pytest.mark.parametrize(
    'force', [[0.0, 150.0, 0.0], [0.0, -150.0, 0.0], [150.0, 0.0, 0.0], [-150.0, 0.0, 0.0]]
)
def test_daqp_holds_the_150_newton_push_at_the_shipped_budget(quadruped_push, force):
    """
    DAQP (the default) under one 1 ms period per cycle: the quadruped stands the push.

    Measured (2-core machine, others' tests beside it): 0 failed cycles in 3000 on most runs, 1 on
    some (a cycle preempted before its solve), tilt <= 3.1 deg as with the offline budget. A
    failed cycle whose update ended within its 1 ms was cut by the budget itself: none may be.
    """
    r = quadruped_push(force=force, seconds=3.0)
    print(f'\n{r.failures} failed cycles ({r.failures_in_time} in time), longest run '
          f'{r.longest_failed_run}, tilt {np.degrees(r.max_tilt):.2f} deg, base {r.base}')
    assert r.budget == (None, None)  # one period
    assert r.failures_in_time == 0, f'{r.failures} failed cycles: {r.codes}'
    assert r.longest_failed_run <= 2, f'{r.failures} failed cycles: {r.codes}'
    assert r.max_tilt < np.radians(10.0), f'tilted {np.degrees(r.max_tilt):.1f} deg'
    np.testing.assert_allclose(r.base, [0.0, 0.0, STAND_HEIGHT], atol=0.02)
