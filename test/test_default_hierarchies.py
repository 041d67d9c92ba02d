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
Strict and GENERALIZED hierarchies with the default settings, on arms nobody tuned for.

The 3-level stack (end effector level 0, an elbow task pulling elsewhere level 1, posture level 2)
under the URDF's torque, position and velocity limits, forward dynamics, 1 ms cycles, on the lwr,
the iiwa of pybullet_data and the Panda of example-robot-data (fingers included). Measured with
the lower levels' damping off (lower_level_damping 0): 19.4 / 83.8 / 31.4 Nm in one cycle
(strict); with the defaults at most 0.8 / 1.3 / 0.7 Nm (strict), 0.7 Nm per step of a sweep
(GENERALIZED); a closed-loop ramp of alpha over 1 s: 1.0 / 1.2 / 1.4 Nm per cycle (the Panda's
was 4.5 with the GENERALIZED levels damped relative to their own tasks' weights only: see
PriorityLevels.damping_scale).
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_conflicting_stack, integrate, STACK_ARMS
import pytest

DT = 0.001
ARMS = STACK_ARMS


@pytest.fixture
def arm(request, lwr_urdf, iiwa_urdf, example_robot_urdf):
    which = request.param
    urdf = {
        'lwr': lambda: lwr_urdf,
        'iiwa': lambda: iiwa_urdf,
        'panda': lambda: example_robot_urdf('panda_description/urdf/panda.urdf'),
    }[which]()

    def make(strategy, alpha=None):
        ee, elbow, q0 = ARMS[which]
        q0 = np.asarray(q0, dtype=float)
        robot = orca.RobotModel()
        robot.load_model_from_file(urdf)
        robot.set_robot_state(q0, np.zeros(q0.size))
        c = orca.Controller(which, robot, strategy)
        add_conflicting_stack(c, frames=(ee, elbow), posture=q0)
        c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
        c.add_constraint(orca.JointPositionLimitConstraint, 'position_limit')
        c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity_limit')
        c.activate_tasks_and_constraints()
        if alpha is not None:
            _priorities(c, alpha)
        return robot, c, q0

    return make


def _priorities(c, alpha):
    for hi in ('ee', 'elbow'):
        for lo in ('elbow', 'posture'):
            if c.get_task(hi).level < c.get_task(lo).level:
                c.set_priority(hi, lo, alpha)


def _closed_loop(robot, c, q0, seconds=2.0, each=None):
    """Run the closed loop; return the torques, calling each(k, q, v) before every update."""
    q, v, taus = q0.copy(), np.zeros(q0.size), []
    for k in range(int(round(seconds / DT))):
        if each is not None:
            each(k, q, v)
        robot.set_robot_state(q, v)
        assert c.update(k * DT, DT), c.get_return_code()
        taus.append(c.get_joint_torque_command().copy())
        q, v = integrate(robot, q, v, taus[-1], DT)
    return np.array(taus)


def _steps(taus):
    return np.abs(np.diff(taus, axis=0)).max(axis=1)


@pytest.mark.parametrize('arm', sorted(ARMS), indirect=True)
def test_strict_levels_do_not_step_the_torques_by_default(arm):
    robot, c, q0 = arm('multi_level_weighted')
    ee = c.get_task('ee')
    lock = [0.0]

    def check(k, q, v):
        if k:  # the last cycle's solution: level 0's rows untouched by the levels below
            assert c.dropped_levels == 0
            x0, x = c.get_problem_at_level(0).x, c.get_problem_at_level(2).x
            lock[0] = max(lock[0], float(np.abs(ee.get_E()[:3] @ (x - x0)).max()))

    steps = _steps(_closed_loop(robot, c, q0, each=check))
    print(f'{c.name}: {steps.max():.2f} Nm at most, level 0 kept to {lock[0]:.1e}')
    assert steps.max() <= 2.0, f'{steps.max():.2f} Nm in one cycle'
    assert lock[0] <= 1e-8


@pytest.mark.parametrize('arm', sorted(ARMS), indirect=True)
def test_generalized_ends_equal_the_pure_strategies_along_the_closed_loop(arm):
    for alpha, pure in ((0.0, 'one_level_weighted'), (1.0, 'multi_level_weighted')):
        robot, gen, q0 = arm('generalized', alpha)
        twin, ref, _ = arm(pure)
        worst = [0.0]

        def compare(k, q, v):
            if k:
                t, t_ref = gen.get_joint_torque_command(), ref.get_joint_torque_command()
                worst[0] = max(worst[0], np.abs(t - t_ref).max() / np.abs(t_ref).max())
            twin.set_robot_state(q, v)  # the same states, the same history
            assert ref.update(k * DT, DT)

        _closed_loop(robot, gen, q0, each=compare)
        print(f'{gen.name}, alpha {alpha} vs {pure}: {worst[0]:.1e} relative')
        assert worst[0] <= 1e-6


@pytest.mark.parametrize('arm', sorted(ARMS), indirect=True)
def test_generalized_priorities_move_the_torques_continuously(arm):
    # alpha swept 0 -> 1 in 1000 steps at states frozen along a closed loop at alpha 0.5
    robot, c, q0 = arm('generalized', 0.5)
    frozen = []
    _closed_loop(robot, c, q0, 1.5, lambda k, q, v: k % 375 == 200 and frozen.append((q, v)))
    worst = []
    for q, v in frozen:
        robot, c, _ = arm('generalized', 0.0)
        robot.set_robot_state(q, v)
        assert c.update(0.0, DT)
        taus = [c.get_joint_torque_command().copy()]
        for i in range(1, 1001):
            _priorities(c, i / 1000)
            assert c.update(i * DT, DT)
            taus.append(c.get_joint_torque_command().copy())
        worst.append(_steps(np.array(taus)).max())
    print(f'{c.name}: sweeps {np.round(worst, 2)} Nm per step at most')
    assert max(worst) <= 2.0


@pytest.mark.parametrize('arm', sorted(ARMS), indirect=True)
def test_a_generalized_priority_ramp_moves_the_torques_continuously(arm):
    """The closed loop with alpha ramped 0 -> 1 over 1 s."""
    robot, c, q0 = arm('generalized', 0.0)
    ramp = _steps(_closed_loop(
        robot, c, q0, each=lambda k, q, v: _priorities(c, min(max(k * DT - 0.5, 0.0), 1.0))
    ))
    print(f'{c.name}: ramp {ramp.max():.2f} Nm per cycle at most')
    assert ramp.max() <= 2.0
