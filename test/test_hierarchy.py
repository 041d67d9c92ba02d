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
"""MULTI_LEVEL_WEIGHTED: strict priorities between levels, weights inside each level."""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_standard_constraints
import pytest

Q = np.array([0.3, 0.7, -0.2, -1.1, 0.4, 0.6, 0.1])
V = np.array([0.2, -0.1, 0.3, 0.0, -0.2, 0.1, 0.0])


def _controller(urdf, strategy, solver, with_elbow=True, with_posture=False):
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    robot.set_robot_state(Q, V)
    c = orca.Controller('c', robot, strategy, solver)
    # these tests are about the hierarchy's semantics, not the real-time bound (that is
    # test_budget.py and test_ros_budget.py, marked real_time_budget): the default budget of one
    # 1 ms period is wall-clock time, which two CPU-burning neighbours halve (measured: cut solves
    # under load); OSQP (ADMM) needs hundreds of iterations here, more than 1 ms even when idle
    c.set_solver_budget(time_budget=0.1)
    # the strict cascade's optimum of each cycle: the default temporal damping spreads a lower
    # level's move over cycles (tested in test_lower_level_damping.py)
    c.set_lower_level_damping(0.0)
    ee = c.add_task(orca.CartesianTask, 'ee', level=0)
    ee.set_control_frame('link_7')
    ee.servo_controller().pid().set_proportional_gain(200.0)
    ee.servo_controller().pid().set_derivative_gain(28.0)
    T = robot.get_frame_pose('link_7')
    T[:3, 3] += [0.05, -0.08, 0.04]
    ee.servo_controller().set_desired(T)
    ee.set_selection_vector([1, 1, 1, 0, 0, 0])  # position: 3 of 7 DoF
    if with_elbow:
        elbow = c.add_task(orca.CartesianTask, 'elbow', level=1)
        elbow.set_control_frame('link_4')
        elbow.servo_controller().pid().set_proportional_gain(300.0)
        elbow.servo_controller().pid().set_derivative_gain(35.0)
        Te = robot.get_frame_pose('link_4')
        Te[:3, 3] += [-0.2, 0.3, -0.1]  # pulls elsewhere
        elbow.servo_controller().set_desired(Te)
        elbow.set_selection_vector([1, 1, 1, 0, 0, 0])
        elbow.set_weight(10.0)  # a weight this large would dominate a single weighted level
    if with_posture:
        post = c.add_task(orca.JointAccelerationTask, 'posture', level=2)
        post.pid().set_proportional_gain(50.0)
        post.pid().set_derivative_gain(14.0)
        post.set_desired(np.zeros(7))
    add_standard_constraints(c)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 0.001), c.get_return_code()
    return robot, c


def _residual(c, name):
    return c.get_task(name).residual(c.get_reduced_solution())


@pytest.mark.parametrize('solver', [orca.QPSolver.DAQP, orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
def test_level_zero_unaffected_by_level_one(lwr_urdf, solver):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    _, alone = _controller(lwr_urdf, MLW, solver, with_elbow=False)
    _, both = _controller(lwr_urdf, MLW, solver, with_elbow=True)
    assert both.get_levels() == [0, 1]
    np.testing.assert_allclose(_residual(both, 'ee'), _residual(alone, 'ee'), atol=1e-8)
    # the level-1 task did change the solution (it had room in the 4 remaining DoF)
    assert np.linalg.norm(both.get_reduced_solution() - alone.get_reduced_solution()) > 1e-3
    # with one weighted level the same two tasks do interfere
    _, weighted = _controller(
        lwr_urdf, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver, with_elbow=True
    )
    assert np.linalg.norm(_residual(weighted, 'ee') - _residual(alone, 'ee')) > 1e-3


def test_three_levels_are_strict(lwr_urdf):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    _, two = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True)
    _, three = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True, with_posture=True)
    assert three.get_levels() == [0, 1, 2]
    np.testing.assert_allclose(_residual(three, 'ee'), _residual(two, 'ee'), atol=1e-8)
    np.testing.assert_allclose(_residual(three, 'elbow'), _residual(two, 'elbow'), atol=1e-8)
    assert three.get_problem_at_level(2).x is not None
    # every level's solution satisfies the constraints
    for lev in three.get_levels():
        p = three.get_problem_at_level(lev)
        assert p.max_constraint_violation(p.x) < 1e-6


def _saturated(urdf, strategy, solver, with_elbow):
    """
    Level 0 pulled with kp 300 under torque limits 40 Nm above gravity.

    Its target is out of reach.
    """
    robot, c = _controller(urdf, strategy, solver, with_elbow=with_elbow)
    lim = np.abs(robot.get_joint_gravity_torques()) + 40.0
    c.get_constraint('JointTorqueLimit').set_limits(-lim, lim)
    c.get_task('ee').servo_controller().pid().set_proportional_gain(300.0)
    assert c.update(0.001, 0.001), c.get_return_code()
    return c, lim


@pytest.mark.parametrize('solver', [orca.QPSolver.DAQP, orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
def test_unachievable_level_zero_leaves_room_to_level_one(lwr_urdf, solver):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    both, lim = _saturated(lwr_urdf, MLW, solver, True)
    alone, _ = _saturated(lwr_urdf, MLW, solver, False)
    weighted, _ = _saturated(lwr_urdf, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver, True)
    # level 0 is achievable with the URDF's torque limits, not with these: its residual stays,
    # limits active
    _, free = _controller(lwr_urdf, MLW, solver, with_elbow=False)
    free.get_task('ee').servo_controller().pid().set_proportional_gain(300.0)
    assert free.update(0.001, 0.001)
    assert np.linalg.norm(_residual(free, 'ee')) < 0.05  # (the regularisation alone costs ~0.02)
    r0 = _residual(alone, 'ee')
    assert np.linalg.norm(r0) > 1.0
    tau = both.get_joint_torque_command()
    assert np.all(np.abs(tau) <= lim + 1e-6)
    assert np.any(np.abs(tau) > lim - 1e-6)
    # level 1 was solved (not dropped) and kept level 0's (unachieved) optimum exactly
    assert both.dropped_levels == 0
    assert both.get_problem_at_level(1).return_code is orca.ReturnCode.SUCCESS
    np.testing.assert_allclose(_residual(both, 'ee'), r0, atol=1e-7)
    # ... while optimising its own task in what was left
    elbow = both.get_task('elbow')
    e_both = np.linalg.norm(elbow.residual(both.get_reduced_solution()))
    e_alone = np.linalg.norm(elbow.residual(alone.get_reduced_solution()))
    assert e_both < 0.97 * e_alone
    # a single weighted level (elbow weight 10) gives level 0 a clearly worse residual
    assert np.linalg.norm(_residual(weighted, 'ee')) > 10.0 * np.linalg.norm(r0)


def test_level_with_no_room_left_keeps_the_solution_above(lwr_urdf):
    """
    Level 0 on the acceleration and torque limits leaves level 1 nothing.

    The cascade returns level 0's solution (strict, feasible) whether the solver finds z = 0 or
    fails on the degenerate problem.
    """
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    robot, c = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True)
    _, alone = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=False)
    for ctrl in (c, alone):
        lim = np.abs(ctrl.robot.get_joint_gravity_torques()) + 8.0
        ctrl.get_constraint('JointTorqueLimit').set_limits(-lim, lim)
        ctrl.get_task('ee').servo_controller().pid().set_proportional_gain(5000.0)
        assert ctrl.update(0.001, 0.001)
    np.testing.assert_allclose(_residual(c, 'ee'), _residual(alone, 'ee'), atol=1e-7)
    elbow = c.get_task('elbow')
    assert (
        np.linalg.norm(elbow.residual(c.get_reduced_solution()))
        <= np.linalg.norm(elbow.residual(alone.get_reduced_solution())) + 1e-9
    )
    tau = c.get_joint_torque_command()
    assert np.all(np.abs(tau) <= lim + 1e-6)


def test_changing_a_level_rebuilds_the_stack(lwr_urdf):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    _, c = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True)
    assert c.get_levels() == [0, 1]
    c.get_task('elbow').set_priority_level(3)
    assert c.get_levels() == [0, 3]
    text = c.describe()
    assert 'level 0 [' in text and 'level 3 [' in text
    assert text.index('ee') < text.index('level 3') < text.index('elbow')


# ---------------------------------------------------------------- GENERALIZED
def _priorities(c, value):
    names = [t.name for t in c.get_tasks()]
    for hi in names:
        for lo in names:
            if c.get_task(hi).level < c.get_task(lo).level:
                c.set_priority(hi, lo, value)


@pytest.mark.parametrize('solver', [orca.QPSolver.DAQP, orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
@pytest.mark.parametrize('posture', [False, True], ids=['two_levels', 'three_levels'])
def test_generalized_ends_are_weighted_and_strict(lwr_urdf, solver, posture):
    GEN = orca.ResolutionStrategy.GENERALIZED
    for value, strategy in (
        (0.0, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED),
        (1.0, orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED),
    ):
        _, gen = _controller(lwr_urdf, GEN, solver, with_posture=posture)
        _priorities(gen, value)
        assert gen.update(0.002, 0.001)
        _, ref = _controller(lwr_urdf, strategy, solver, with_posture=posture)
        assert ref.update(0.002, 0.001)
        tau, tau_ref = gen.get_joint_torque_command(), ref.get_joint_torque_command()
        scale = np.abs(tau_ref).max()
        np.testing.assert_allclose(tau, tau_ref, atol=1e-6 * scale, rtol=0)
        for name in ('ee', 'elbow'):
            r, r_ref = _residual(gen, name), _residual(ref, name)
            np.testing.assert_allclose(r, r_ref, atol=1e-6 * max(1.0, np.abs(r_ref).max()), rtol=0)
    # in between, level 0 gets a residual between the two ends
    _, mid = _controller(lwr_urdf, GEN, solver, with_posture=posture)
    _priorities(mid, 0.5)
    assert mid.update(0.002, 0.001)
    _, w = _controller(
        lwr_urdf, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver, with_posture=posture
    )
    _, s = _controller(
        lwr_urdf, orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED, solver, with_posture=posture
    )
    for c in (w, s):
        assert c.update(0.002, 0.001)
    n = [np.linalg.norm(_residual(c, 'ee')) for c in (s, mid, w)]
    assert n[0] + 1e-3 < n[1] < n[2] - 1e-3


def _ramp_run(urdf, priority, dt=0.001, duration=1.5):
    """
    Run a closed loop on the rigid-body model.

    Returns the largest per-cycle torque change in [0.25, 1.25] s.
    """
    from orca_ros.examples.common import integrate

    robot, c = _controller(urdf, orca.ResolutionStrategy.GENERALIZED, orca.QPSolver.PROXQP)
    c.get_task('ee').servo_controller().pid().set_proportional_gain(100.0)
    c.get_task('ee').servo_controller().pid().set_derivative_gain(20.0)
    c.get_task('elbow').servo_controller().pid().set_proportional_gain(100.0)
    c.get_task('elbow').servo_controller().pid().set_derivative_gain(20.0)
    q, v, t = Q.copy(), V.copy(), 0.0
    taus = []
    for _ in range(int(round(duration / dt))):
        c.set_priority('ee', 'elbow', priority(t))
        robot.set_robot_state(q, v)
        assert c.update(t, dt), c.get_return_code()
        tau = c.get_joint_torque_command()
        assert np.all(np.isfinite(tau))
        taus.append(tau)
        q, v = integrate(robot, q, v, tau, dt)
        t += dt
    steps = np.abs(np.diff(np.array(taus), axis=0)).max(axis=1)
    return steps[int(0.25 / dt): int(1.25 / dt)].max()


def test_generalized_priority_ramp_gives_continuous_torques(lwr_urdf):
    ramp = _ramp_run(lwr_urdf, lambda t: min(max(t - 0.25, 0.0), 1.0))  # 0 -> 1 over 1 s
    switch = _ramp_run(lwr_urdf, lambda t: 0.0 if t < 0.75 else 1.0)  # the same change at once
    assert switch > 5.0  # weighted -> strict at once: a torque jump of several Nm in one cycle
    assert ramp < 0.15 * switch and ramp < 2.0  # the ramp: no jump (Nm per 1 ms cycle)


@pytest.mark.parametrize('strategy', ['multi_level_weighted', 'generalized', 'one_level_weighted'])
def test_ramping_out_a_higher_level_task_is_continuous(strategy):
    """
    The shipped arm configuration (end-effector at level 0, posture at level 1).

    Switching the end-effector task off with its 0.5 s ramp releases its lock progressively (no
    torque jump when the ramp ends).
    """
    from orca_ros.configuration.controller_builder import build_from_config
    from orca_ros.examples.common import integrate
    import yaml

    with open(orca.share_path('config', 'lwr_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    cfg['resolution_strategy'] = strategy
    setup = build_from_config(cfg)
    robot, c = setup.robot, setup.controller
    robot.set_gravity(np.array([0.0, 0.0, -9.81]))
    q, v, t, dt = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]), np.zeros(7), 0.0, 0.001
    c.activate_tasks_and_constraints()
    ee = c.get_task('ee')
    taus = []
    for k in range(2500):
        if k == 500:
            target = robot.get_frame_pose('link_7')
            target[:3, 3] += [0.08, -0.10, 0.05]
            ee.servo_controller().set_desired(target)
        if k == 1500:
            ee.deactivate()
        robot.set_robot_state(q, v)
        assert c.update(t, dt), c.get_return_code()
        taus.append(c.get_joint_torque_command())
        q, v = integrate(robot, q, v, taus[-1], dt)
        t += dt
    assert ee.is_deactivated()
    steps = np.abs(np.diff(np.array(taus[1500:]), axis=0)).max()
    assert steps < 1.0, f'{steps:.3f} Nm in one cycle while the task ramps out'


def test_yaml_levels_and_priorities():
    from orca_ros.configuration.controller_builder import build_from_config, ConfigError
    import yaml

    with open(orca.share_path('config', 'lwr_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    setup = build_from_config(cfg)
    assert setup.controller.resolution_strategy is orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    assert setup.controller.get_levels() == [0, 1]
    cfg['resolution_strategy'] = 'generalized'
    cfg['tasks']['ee']['priority_over'] = {'posture': 0.3}
    assert build_from_config(cfg).controller.get_priority('ee', 'posture') == 0.3
    for bad in ({'nope': 0.3}, {'posture': 1.5}):
        cfg['tasks']['ee']['priority_over'] = bad
        with pytest.raises(ConfigError, match='priority_over'):
            build_from_config(cfg)
    cfg['tasks']['ee']['priority_over'] = {'posture': 0.3}
    cfg['resolution_strategy'] = 'multi_level_weighted'  # priority values need GENERALIZED
    with pytest.raises(ConfigError, match='GENERALIZED'):
        build_from_config(cfg)
