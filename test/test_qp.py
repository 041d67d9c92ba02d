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
QP solutions.

Constraints hold, equality-only problems match the closed-form KKT solution of the reference's full
formulation, and OSQP agrees with ProxQP.
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_standard_constraints
import pinocchio as pin
import pytest


def _arm(urdf, solver, constrained=True, seed=0):
    rng = np.random.default_rng(seed)
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    lo, hi = robot.get_joint_position_limits()
    q = rng.uniform(lo * 0.8, hi * 0.8)
    v = rng.uniform(-1.0, 1.0, 7)
    robot.set_robot_state(q, v)
    c = orca.Controller('c', robot, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED, solver)
    cart = c.add_task(orca.CartesianTask, 'cart')
    cart.set_control_frame('link_7')
    cart.servo_controller().pid().set_proportional_gain([1000, 1000, 1000, 10, 10, 10])
    cart.servo_controller().pid().set_derivative_gain([100, 100, 100, 1, 1, 1])
    cart.servo_controller().set_desired(
        orca.make_transform([0.4, -0.3, 0.5], orca.rotation_from_rpy(np.pi, 0, 0))
    )
    post = c.add_task(orca.JointAccelerationTask, 'posture')
    post.set_weight(1e-2)
    post.pid().set_proportional_gain(50.0)
    post.pid().set_derivative_gain(14.0)
    post.set_desired(np.zeros(7))
    trq_task = c.add_task(orca.JointTorqueTask, 'torque')
    trq_task.set_weight(1e-5)
    trq_task.set_desired(rng.uniform(-5, 5, 7))
    if constrained:
        trq, pos, vel = add_standard_constraints(c)
        trq.set_limits(-np.full(7, 40.0), np.full(7, 40.0))  # tight: some bounds are active
        acc = c.add_constraint(orca.JointAccelerationLimitConstraint, 'acc')
        acc.set_limits(-np.full(7, 30.0), np.full(7, 30.0))
    c.activate_tasks_and_constraints()
    return robot, c, rng


@pytest.mark.parametrize('solver', [orca.QPSolver.DAQP, orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
def test_every_solution_satisfies_its_constraints(lwr_urdf, solver):
    active_seen = 0
    for seed in range(8):
        robot, c, _ = _arm(lwr_urdf, solver, seed=seed)
        assert c.update(0.0, 0.001), c.get_return_code()
        x = c.get_reduced_solution()
        problem = c.get_problem_at_level(0)
        assert problem.max_constraint_violation(x) < 1e-6
        # and physically: torques within +-40 Nm, accelerations within +-30 rad/s^2 and the
        # predicted bounds
        tau = c.get_joint_torque_command()
        assert np.all(np.abs(tau) <= 40.0 + 1e-6)
        qdd = c.get_joint_acceleration_command()
        assert np.all(np.abs(qdd) <= 30.0 + 1e-6)
        for name in ('JointPositionLimit', 'JointVelocityLimit'):
            assert c.get_constraint(name).violation(x) < 1e-6
        active_seen += int(
            np.any(np.abs(np.abs(tau) - 40.0) < 1e-6) or np.any(np.abs(np.abs(qdd) - 30) < 1e-6)
        )
        # the dynamics hold on the full solution: the torque, applied to the arm, gives the QP's
        # acceleration. Pinocchio's forward dynamics (ABA) on a fresh Data, not the controller's
        # M and n (from which the reduced problem builds the torque: M qdd + n would hold by
        # construction). Measured 1.8e-12 rad/s^2 (round-off through M^-1 on 30 rad/s^2); 5x
        chi = c.get_solution()
        model = robot.model
        q, v = robot.get_joint_positions(), robot.get_joint_velocities()
        qdd = pin.aba(model, model.createData(), q, v, chi[7:14])
        np.testing.assert_allclose(qdd, chi[:7], rtol=0, atol=1e-11)
    assert active_seen >= 3, 'the scenario should exercise active constraints'


def test_osqp_and_proxqp_agree(lwr_urdf):
    for seed in range(8):
        _, cp, _ = _arm(lwr_urdf, orca.QPSolver.PROXQP, seed=seed)
        _, co, _ = _arm(lwr_urdf, orca.QPSolver.OSQP, seed=seed)
        for t in (0.0, 0.001, 0.002):  # warm-started solves too
            assert cp.update(t, 0.001) and co.update(t, 0.001)
            xp, xo = cp.get_solution(), co.get_solution()
            assert np.linalg.norm(xo - xp) <= 1e-6 * np.linalg.norm(xp)


@pytest.mark.parametrize('solver', [orca.QPSolver.DAQP, orca.QPSolver.PROXQP, orca.QPSolver.OSQP])
def test_equality_only_problem_matches_full_kkt(lwr_urdf, solver):
    """
    Compare the reduced QP with the reference's full formulation chi = [q_ddot, tau].

    The full one has the dynamics as equality and is solved in closed form from its KKT system
    (built here independently from Pinocchio's terms).
    """
    robot, c, _ = _arm(lwr_urdf, solver, constrained=False, seed=3)
    assert c.update(0.0, 0.001)
    n = 7
    M = robot.get_mass_matrix().copy()
    h = robot.get_joint_gravity_and_coriolis_torques()
    v = robot.get_joint_velocities()
    cart, post, trq = c.get_task('cart'), c.get_task('posture'), c.get_task('torque')
    J = robot.get_frame_jacobian('link_7')
    a_des = cart.servo_controller().get_command()
    reg = c.global_regularisation
    blocks = [  # (weight, E on chi, f)
        (
            1.0,
            np.hstack((J, np.zeros((6, n)))),
            a_des - robot.get_frame_bias_acceleration('link_7'),
        ),
        (post.get_weight(), np.hstack((np.eye(n), np.zeros((n, n)))), post.get_f()),
        (trq.get_weight(), np.hstack((np.zeros((n, n)), np.eye(n))), trq.get_desired()),
        (reg.get_weight(), np.hstack((np.eye(n), np.zeros((n, n)))), -reg.damping * v),
    ]
    H = sum(w * E.T @ E for w, E, _ in blocks)
    g = -sum(w * E.T @ f for w, E, f in blocks)
    A = np.hstack((-M, np.eye(n)))  # [-M  S^T] chi = n
    K = np.block([[H, A.T], [A, np.zeros((n, n))]])
    chi = np.linalg.solve(K, np.concatenate((-g, h)))[: 2 * n]
    np.testing.assert_allclose(c.get_solution(), chi, rtol=1e-7, atol=1e-7)
    # the controller's own KKT fallback is the same solution
    np.testing.assert_allclose(c.compute_kkt_torques(), chi[n:], rtol=1e-7, atol=1e-7)


def test_infeasible_problem_reports_failure_and_kkt_fallback_is_finite(lwr_urdf):
    robot, c, _ = _arm(lwr_urdf, orca.QPSolver.PROXQP, seed=1)
    acc = c.get_constraint('acc')
    acc.set_limits(np.full(7, 5.0), np.full(7, 5.0))  # q_ddot = 5 for all joints ...
    c.get_constraint('JointTorqueLimit').set_limits(
        -np.full(7, 0.1), np.full(7, 0.1)
    )  # ... with ~no torque
    assert not c.update(0.0, 0.001)
    assert not c.solution_found()
    assert c.get_return_code() is not orca.ReturnCode.SUCCESS
    assert np.all(np.isfinite(c.compute_kkt_torques()))
