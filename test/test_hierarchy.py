"""MULTI_LEVEL_WEIGHTED: strict priorities between levels, weights inside each level."""
import numpy as np
import pytest

import orca_ros as orca
from orca_ros.examples.common import add_standard_constraints

Q = np.array([0.3, 0.7, -0.2, -1.1, 0.4, 0.6, 0.1])
V = np.array([0.2, -0.1, 0.3, 0.0, -0.2, 0.1, 0.0])


def _controller(urdf, strategy, solver, with_elbow=True, with_posture=False):
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    robot.set_robot_state(Q, V)
    c = orca.Controller("c", robot, strategy, solver)
    ee = c.add_task(orca.CartesianTask, "ee", level=0)
    ee.set_control_frame("link_7")
    ee.servo_controller().pid().set_proportional_gain(200.0)
    ee.servo_controller().pid().set_derivative_gain(28.0)
    T = robot.get_frame_pose("link_7")
    T[:3, 3] += [0.05, -0.08, 0.04]
    ee.servo_controller().set_desired(T)
    ee.set_selection_vector([1, 1, 1, 0, 0, 0])  # position: 3 of 7 DoF
    if with_elbow:
        elbow = c.add_task(orca.CartesianTask, "elbow", level=1)
        elbow.set_control_frame("link_4")
        elbow.servo_controller().pid().set_proportional_gain(300.0)
        elbow.servo_controller().pid().set_derivative_gain(35.0)
        Te = robot.get_frame_pose("link_4")
        Te[:3, 3] += [-0.2, 0.3, -0.1]  # pulls elsewhere
        elbow.servo_controller().set_desired(Te)
        elbow.set_selection_vector([1, 1, 1, 0, 0, 0])
        elbow.set_weight(10.0)  # a weight this large would dominate a single weighted level
    if with_posture:
        post = c.add_task(orca.JointAccelerationTask, "posture", level=2)
        post.pid().set_proportional_gain(50.0)
        post.pid().set_derivative_gain(14.0)
        post.set_desired(np.zeros(7))
    add_standard_constraints(c)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 0.001), c.get_return_code()
    return robot, c


def _residual(c, name):
    return c.get_task(name).residual(c.get_reduced_solution())


@pytest.mark.parametrize("solver", [orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
def test_level_zero_unaffected_by_level_one(lwr_urdf, solver):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    _, alone = _controller(lwr_urdf, MLW, solver, with_elbow=False)
    _, both = _controller(lwr_urdf, MLW, solver, with_elbow=True)
    assert both.get_levels() == [0, 1]
    np.testing.assert_allclose(_residual(both, "ee"), _residual(alone, "ee"), atol=1e-8)
    # the level-1 task did change the solution (it had room in the 4 remaining DoF)
    assert np.linalg.norm(both.get_reduced_solution() - alone.get_reduced_solution()) > 1e-3
    # with one weighted level the same two tasks do interfere
    _, weighted = _controller(lwr_urdf, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver, with_elbow=True)
    assert np.linalg.norm(_residual(weighted, "ee") - _residual(alone, "ee")) > 1e-3


def test_three_levels_are_strict(lwr_urdf):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    _, two = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True)
    _, three = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True, with_posture=True)
    assert three.get_levels() == [0, 1, 2]
    np.testing.assert_allclose(_residual(three, "ee"), _residual(two, "ee"), atol=1e-8)
    np.testing.assert_allclose(_residual(three, "elbow"), _residual(two, "elbow"), atol=1e-8)
    assert three.get_problem_at_level(2).x is not None
    # every level's solution satisfies the constraints
    for lev in three.get_levels():
        p = three.get_problem_at_level(lev)
        assert p.max_constraint_violation(p.x) < 1e-6


def _saturated(urdf, strategy, solver, with_elbow):
    """Level 0 pulled with kp 300 under torque limits 40 Nm above gravity: its target is out of reach."""
    robot, c = _controller(urdf, strategy, solver, with_elbow=with_elbow)
    lim = np.abs(robot.get_joint_gravity_torques()) + 40.0
    c.get_constraint("JointTorqueLimit").set_limits(-lim, lim)
    c.get_task("ee").servo_controller().pid().set_proportional_gain(300.0)
    assert c.update(0.001, 0.001), c.get_return_code()
    return c, lim


@pytest.mark.parametrize("solver", [orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
def test_unachievable_level_zero_leaves_room_to_level_one(lwr_urdf, solver):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    both, lim = _saturated(lwr_urdf, MLW, solver, True)
    alone, _ = _saturated(lwr_urdf, MLW, solver, False)
    weighted, _ = _saturated(lwr_urdf, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver, True)
    # level 0 is achievable with the URDF's torque limits, not with these: its residual stays, limits active
    _, free = _controller(lwr_urdf, MLW, solver, with_elbow=False)
    free.get_task("ee").servo_controller().pid().set_proportional_gain(300.0)
    assert free.update(0.001, 0.001)
    assert np.linalg.norm(_residual(free, "ee")) < 0.05  # (the regularisation alone costs ~0.02)
    r0 = _residual(alone, "ee")
    assert np.linalg.norm(r0) > 1.0
    tau = both.get_joint_torque_command()
    assert np.all(np.abs(tau) <= lim + 1e-6)
    assert np.any(np.abs(tau) > lim - 1e-6)
    # level 1 was solved (not dropped) and kept level 0's (unachieved) optimum exactly
    assert both.dropped_levels == 0
    assert both.get_problem_at_level(1).return_code is orca.ReturnCode.SUCCESS
    np.testing.assert_allclose(_residual(both, "ee"), r0, atol=1e-7)
    # ... while optimising its own task in what was left
    elbow = both.get_task("elbow")
    e_both = np.linalg.norm(elbow.residual(both.get_reduced_solution()))
    e_alone = np.linalg.norm(elbow.residual(alone.get_reduced_solution()))
    assert e_both < 0.97 * e_alone
    # a single weighted level (elbow weight 10) gives level 0 a clearly worse residual
    assert np.linalg.norm(_residual(weighted, "ee")) > 10.0 * np.linalg.norm(r0)


def test_level_with_no_room_left_keeps_the_solution_above(lwr_urdf):
    """Level 0 on the acceleration and torque limits leaves level 1 nothing: the cascade returns level 0's
    solution (strict, feasible) whether the solver finds z = 0 or fails on the degenerate problem."""
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    robot, c = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True)
    _, alone = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=False)
    for ctrl in (c, alone):
        lim = np.abs(ctrl.robot.get_joint_gravity_torques()) + 8.0
        ctrl.get_constraint("JointTorqueLimit").set_limits(-lim, lim)
        ctrl.get_task("ee").servo_controller().pid().set_proportional_gain(5000.0)
        assert ctrl.update(0.001, 0.001)
    np.testing.assert_allclose(_residual(c, "ee"), _residual(alone, "ee"), atol=1e-7)
    elbow = c.get_task("elbow")
    assert (np.linalg.norm(elbow.residual(c.get_reduced_solution()))
            <= np.linalg.norm(elbow.residual(alone.get_reduced_solution())) + 1e-9)
    tau = c.get_joint_torque_command()
    assert np.all(np.abs(tau) <= lim + 1e-6)


def test_changing_a_level_rebuilds_the_stack(lwr_urdf):
    MLW = orca.ResolutionStrategy.MULTI_LEVEL_WEIGHTED
    _, c = _controller(lwr_urdf, MLW, orca.QPSolver.PROXQP, with_elbow=True)
    assert c.get_levels() == [0, 1]
    c.get_task("elbow").set_priority_level(3)
    assert c.get_levels() == [0, 3]
    text = c.describe()
    assert "level 0 [" in text and "level 3 [" in text
    assert text.index("ee") < text.index("level 3") < text.index("elbow")
