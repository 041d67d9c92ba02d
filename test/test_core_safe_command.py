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
The core's failed cycle: its command is the safe one, so a loop that applies it brakes the robot.

A user loop on the core applies ``get_joint_torque_command()`` whatever ``update`` returned. A
failed cycle used to leave the last solved torques there, and holding them spun an arm's wrist
up. Now the command is hold = g(q) - M(q) k_d v clipped to the torque limits, the last good
command fading into it over the ramp: every joint's speed then obeys a = -k_d v - M^-1 c(q, v)
(the rigid-body dynamics under the hold), so it decays as exp(-k_d t) up to the Coriolis
coupling, which is quadratic in v and vanishes as the arm slows.
"""

from types import SimpleNamespace

import numpy as np
import orca_ros as orca
from orca_ros.examples import quadruped as quad
from orca_ros.examples.common import integrate
import pytest

DT = 0.001
K_D, RAMP = 10.0, 0.2  # the controller's defaults (the node's safe_damping and safe_ramp)
Q0 = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0])
SPEED_UP = 0.2  # s of 5 rad/s^2 on every joint: 1 rad/s when the fault starts
FAULT = 1.0  # s of an infeasible problem
INFEASIBLE = (np.full(7, 1e4), np.full(7, 1e4 + 1.0))  # accelerations no torque limit allows
FREE = (np.full(7, -np.inf), np.full(7, np.inf))


def _arm(compiled=True):
    """Make the shipped arm's controller: a posture task, torque and (free) acceleration limits."""
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(Q0, np.zeros(7))
    c = orca.Controller('c', robot, compiled=compiled)
    post = c.add_task(orca.JointAccelerationTask, 'posture')
    post.pid().set_proportional_gain(0.0)
    post.pid().set_derivative_gain(0.0)
    post.set_desired(Q0, np.zeros(7), np.full(7, 5.0))  # every joint speeds up at 5 rad/s^2
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    acc = c.add_constraint(orca.JointAccelerationLimitConstraint, 'acc_limit')
    c.activate_tasks_and_constraints()
    return robot, c, acc


def _hold(robot, v, gravity=True):
    """g(q) - M(q) K_D v at the robot's state, clipped to the URDF's efforts (the definition)."""
    nb = robot.get_configuration_space_dimension() - robot.get_nr_of_degrees_of_freedom()
    lim = robot.get_joint_torque_limits()
    g = robot.get_generalized_gravity_torques()[nb:] if gravity else 0.0
    return np.clip(g - K_D * robot.get_mass_matrix()[nb:, nb:] @ v, -lim, lim)


def _run(held_by_the_core=True, compiled=True):
    """
    Speed the arm up, then fail every cycle for FAULT s while the loop applies a command.

    ``held_by_the_core``: the loop applies ``get_joint_torque_command()``; False: the last
    successful command (what the core gave before). Returns the speeds (largest joint's, one per
    failed cycle), the commands applied, the holds by definition, the last good command, the
    speed at the fault's start, the controller, robot and state.
    """
    robot, c, acc = _arm(compiled)
    q, v, t = Q0.copy(), np.zeros(7), 0.0
    for _ in range(int(round(SPEED_UP / DT))):
        robot.set_robot_state(q, v)
        assert c.update(t, DT)
        last = c.get_joint_torque_command()
        q, v = integrate(robot, q, v, last, DT)
        t += DT
    start = np.abs(v).max()
    acc.set_limits(*INFEASIBLE)
    speeds, commands, holds, safe = [], [], [], []
    for _ in range(int(round(FAULT / DT))):
        robot.set_robot_state(q, v)
        assert not c.update(t, DT)
        safe.append(c.command_is_safe())
        tau = c.get_joint_torque_command() if held_by_the_core else last
        holds.append(_hold(robot, v))
        commands.append(tau)
        q, v = integrate(robot, q, v, tau, DT)
        speeds.append(np.abs(v).max())
        t += DT
    return (np.array(speeds), np.array(commands), np.array(holds), last, start, all(safe),
            SimpleNamespace(c=c, robot=robot, acc=acc, q=q, v=v, t=t))


@pytest.mark.parametrize('compiled', [True, False])
def test_an_infeasible_second_applied_from_the_core_brakes_the_arm(compiled):
    speeds, cmds, holds, last, start, all_safe, end = _run(compiled=compiled)
    lim = end.robot.get_joint_torque_limits()
    print(f'\nspeed at the fault {start:.4f} rad/s, at the end of the ramp '
          f'{speeds[int(round(RAMP / DT)) - 1]:.4f}, after {FAULT} s {speeds[-1]:.2e} rad/s')
    assert start > 0.99  # the scenario: the arm moving at 1 rad/s when the fault starts
    assert all_safe  # every cycle failed (asserted in _run) and said its command is the safe one
    diagnosis = end.c.diagnose()
    assert not diagnosis.feasible
    assert set(diagnosis.conflicting_constraints) == {'torque_limit', 'acc_limit'}
    # bounded and finite, every cycle
    assert np.isfinite(cmds).all()
    assert (np.abs(cmds) <= lim).all()
    # faded: the first failed cycle sends the last good command (fade at 0), each later step of
    # the ramp is at most dt/ramp of the way to the hold plus the hold's own change
    n_ramp = int(round(RAMP / DT))
    np.testing.assert_array_equal(cmds[0], last)
    a = np.arange(1, n_ramp) * DT / RAMP
    steps = np.abs(np.diff(cmds[:n_ramp], axis=0))
    allowed = ((DT / RAMP) * np.abs(holds[1:n_ramp] - last)
               + np.abs(np.diff(holds[:n_ramp], axis=0)))
    assert (steps <= allowed + 1e-9).all()
    unfaded = np.abs(holds[0] - last).max()  # the step the ramp spares the drives
    assert steps.max() < 10 * (DT / RAMP) * unfaded  # (the hold's own change: far less)
    np.testing.assert_allclose(cmds[n_ramp + 1:], holds[n_ramp + 1:], atol=1e-9)  # then the hold
    np.testing.assert_allclose(cmds[1:n_ramp], ((1 - a)[:, None] * last
                                                + a[:, None] * holds[1:n_ramp]), atol=1e-9)
    # braking: after the ramp each joint's speed is (1 - k_d dt) times the last one's (explicit
    # Euler of a = -k_d v), less the Coriolis coupling M^-1 c(q, v), quadratic in v: a lag while
    # the arm is fast, allowed one time constant 1/k_d (a factor e); in the last 0.25 s, below
    # 1e-2 rad/s, the coupling is proportional to |v| and the decay rate is k_d's within 1 %
    per_step = 1.0 - K_D * DT
    after = len(speeds) - n_ramp
    assert speeds[-1] < speeds[n_ramp - 1] * per_step ** after * np.e
    assert speeds[-1] < 1e-3 * start
    late = int(round(0.25 / DT))
    assert speeds[-late - 1] < 1e-2
    rate = np.log(speeds[-late - 1] / speeds[-1]) / (late * DT)
    assert rate == pytest.approx(-np.log(per_step) / DT, rel=0.01)
    # the fault clears: a feasible problem again, the solution's command back
    end.acc.set_limits(*FREE)
    end.robot.set_robot_state(end.q, end.v)
    assert end.c.update(end.t, DT)
    assert not end.c.command_is_safe()
    np.testing.assert_array_equal(end.c.get_joint_torque_command(), end.c.get_solution()[7:14])


def test_the_last_torque_held_instead_runs_the_arm_away():
    """The counterfactual: the scenario is one the old behaviour (last torque held) fails."""
    held, _, _, _, start, _, _ = _run(held_by_the_core=False)
    safe = _run()[0]
    print(f'\nlast torque held: {start:.3f} -> {held[-1]:.1f} rad/s; safe command: '
          f'{safe[-1]:.2e} rad/s')
    assert held[-1] > start  # the held torque keeps speeding the arm up
    assert held[-1] > 1e3 * safe[-1]


def test_a_second_fault_fades_in_again_from_the_new_good_command():
    """A success restarts the fade: the next failure starts from that success's command."""
    robot, c, acc = _arm()
    q, v = Q0.copy(), np.full(7, 0.5)
    robot.set_robot_state(q, v)
    assert c.update(0.0, DT)
    acc.set_limits(*INFEASIBLE)
    for k in range(1, 400):  # past the ramp: the hold itself
        assert not c.update(k * DT, DT)
    np.testing.assert_allclose(c.get_joint_torque_command(), _hold(robot, v), atol=1e-9)
    acc.set_limits(*FREE)
    assert c.update(0.4, DT) and not c.command_is_safe()
    good = c.get_joint_torque_command()
    acc.set_limits(*INFEASIBLE)
    assert not c.update(0.401, DT) and c.command_is_safe()
    np.testing.assert_array_equal(c.get_joint_torque_command(), good)  # the fade at 0 again


@pytest.mark.parametrize('by_hardware', [False, True])
def test_drives_that_compensate_gravity_get_no_gravity_in_the_safe_command(by_hardware):
    robot, c, acc = _arm()
    c.remove_gravity_torques_from_solution(by_hardware)
    c.set_safe_command(K_D, 0.0)  # no fade: the hold at once
    v = np.linspace(-1.0, 1.0, 7)
    robot.set_robot_state(Q0, v)
    acc.set_limits(*INFEASIBLE)
    assert not c.update(0.0, DT) and c.command_is_safe()
    np.testing.assert_allclose(c.get_joint_torque_command(), _hold(robot, v, not by_hardware),
                               atol=1e-9)


def test_safe_command_settings_are_checked():
    _, c, _ = _arm()
    assert (c.safe_command.damping, c.safe_command.ramp) == (K_D, RAMP)
    for bad in [(-1.0, 0.2), (10.0, -0.1), (np.nan, 0.2), (10.0, np.inf)]:
        with pytest.raises(ValueError, match='safe command'):
            c.set_safe_command(*bad)


def test_floating_base_safe_command_is_the_actuated_part():
    """A quadruped in the air, its QP infeasible: the hold of its 12 joints, base left out."""
    robot = quad.make_robot()
    n = robot.get_nr_of_degrees_of_freedom()
    v = np.linspace(-0.5, 0.5, n)
    robot.set_robot_state(robot.get_world_to_base_transform(), quad.STAND_Q,
                          np.array([0.1, 0.0, -0.2, 0.0, 0.3, 0.0]), v, quad.GRAVITY)
    c = orca.Controller('c', robot)
    c.add_task(orca.JointAccelerationTask, 'posture')
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    acc = c.add_constraint(orca.JointAccelerationLimitConstraint, 'acc_limit')
    c.activate_tasks_and_constraints()
    c.set_safe_command(K_D, 0.0)
    acc.set_limits(np.full(n, 1e4), np.full(n, 1e4 + 1.0))
    assert not c.update(0.0, DT) and c.command_is_safe()
    cmd = c.get_joint_torque_command()
    assert cmd.shape == (n,)
    np.testing.assert_allclose(cmd, _hold(robot, v), atol=1e-9)
