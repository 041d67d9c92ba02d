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
Contacts that stay, and a quadruped that takes a push (issue 11, item 4).

The quadruped stands in PyBullet and gets a lateral push on its trunk for 0.1 s. With the
existence condition J nu_dot + J_dot nu = 0 a foot set sliding keeps its speed (measured: feet
slide ~105 mm at 100 N); with J nu_dot + J_dot nu = -gain J nu the slip decays and the feet stay
within 5 mm. At 150 N the example's standing controller holds from every side; with the trunk's
axes weighted alike, or with the position limits' default braking, it tips over.

Budget: these runs judge physics, so they keep the suite's offline budget (10 s per cycle, see
conftest; every run asserts it). Under the shipped budget (one 1 ms period) DAQP, the default,
holds the push as well, with no failed cycle (test_budget.py); ProxQP and OSQP do not hold it
there, so they are tested here with the offline budget only. Measured on the push from behind,
3000 cycles, 1 ms budget: ProxQP varies from run to run (a landing cycle cut short or not decides
it), 2222-2487 failed cycles and a fall (tilt 24-58 deg) on 5 of 7 runs, 4 and 21 failed cycles
standing on the 2 others; OSQP 2495 failed cycles and a 36-38 deg tilt on every run (its floor
of 200 iterations is its whole cap at 1 ms, so the machine's load does not change it).
"""

import numpy as np
from orca_ros.examples.quadruped import make_robot, QuadrupedController, STAND_HEIGHT
import pytest

OFFLINE = (10.0, None)  # the suite's solve budget: 10 s per cycle, the solver's iteration cap


def test_without_feedback_a_pushed_foot_keeps_sliding(quadruped_push):
    r = quadruped_push(gain=0.0)
    assert r.budget == OFFLINE
    assert r.failures == 0
    assert r.slide > 0.05  # the defect the feedback removes


def test_velocity_feedback_keeps_the_feet_in_place_under_a_push(quadruped_push):
    r = quadruped_push(gain=200.0)
    assert r.budget == OFFLINE
    assert r.failures == 0
    assert r.slide < 5e-3, f'a foot slid {r.slide * 1e3:.1f} mm'
    np.testing.assert_allclose(r.base, [0.0, 0.0, STAND_HEIGHT], atol=5e-3)  # the trunk recovered


def test_the_gain_is_checked():
    robot = make_robot()
    qc = QuadrupedController(robot, 'daqp')
    with pytest.raises(ValueError, match='velocity gain must be >= 0'):
        qc.contacts['FL'].set_velocity_feedback_gain(-1.0)


HOME = [0.0, 0.0, STAND_HEIGHT]


@pytest.mark.parametrize(
    'force', [[0.0, 150.0, 0.0], [0.0, -150.0, 0.0], [150.0, 0.0, 0.0], [-150.0, 0.0, 0.0]]
)
def test_a_150_newton_push_from_any_side_is_recovered(quadruped_push, force):
    """
    No fall, no failed cycle, the trunk back home (measured: tilt <= 3.1 deg, 0 failures).

    The example's defaults: horizontal weight 5, contact velocity gain 200 /s, joint braking
    100 rad/s^2 (see QuadrupedController). Offline budget; the shipped one: test_budget.py.
    """
    r = quadruped_push(force=force, seconds=3.0)
    assert r.budget == OFFLINE
    assert r.failures == 0, r.codes
    assert r.max_tilt < np.radians(10.0), f'tilted {np.degrees(r.max_tilt):.1f} deg'
    np.testing.assert_allclose(r.base, HOME, atol=0.02)


@pytest.mark.parametrize('solver', ['proxqp', 'osqp'])
def test_the_other_solvers_hold_the_push_with_the_offline_budget(quadruped_push, solver):
    """
    With 10 s per cycle. Measured on the push from behind: no failed cycle with either.

    OSQP calls the rigid problem of 1 cycle at the push primal infeasible; the elastic fallback,
    solved by DAQP whatever the controller's solver (optim/elastic_contacts.py), carries it. Solved
    by OSQP, that fallback hit its iteration cap and 4 cycles in a row failed. Under the shipped
    1 ms budget neither solver holds the push (see the module's docstring).
    """
    r = quadruped_push(force=[150.0, 0.0, 0.0], seconds=3.0, solver=solver)
    assert r.budget == OFFLINE
    assert r.failures == 0, r.codes
    assert r.max_tilt < np.radians(10.0), f'tilted {np.degrees(r.max_tilt):.1f} deg'
    np.testing.assert_allclose(r.base, HOME, atol=0.02)


@pytest.mark.parametrize(
    'setting',
    [{'horizontal_weight': 1.0}, {'joint_braking': 5.0}, {'contact_velocity_gain': 0.0}],
)
def test_without_any_one_setting_the_quadruped_tips_over(quadruped_push, setting):
    """
    The three settings the push needs, each taken back to its former value: the robot tips over.

    Trunk axes weighted alike: during the push the far feet carry ~190 N and ~80 N sideways; after
    it the trunk's height servo unloads them to ~40 N and the lateral force goes with it.
    Braking at 5 rad/s^2: a knee 1.2 rad from its limit may not turn faster than 3.5 rad/s, and the
    unloaded legs cannot follow the trunk. No velocity feedback: the feet set sliding keep sliding.

    Even so the controller never stops commanding for long: a level-0 QP that has no solution with
    rigid contacts is solved again with the existence conditions as a heavy cost (elastic
    contacts). Before them it failed ~1500 cycles in a row, holding its last command.
    """
    r = quadruped_push(force=150.0, seconds=3.0, **setting)
    assert r.budget == OFFLINE
    assert r.max_tilt > np.radians(45.0)  # on its side
    assert r.longest_failed_run <= 10
    if 'contact_velocity_gain' in setting:
        assert r.relaxed > 100  # cycles the elastic contacts carried


@pytest.mark.parametrize(
    'base_velocity, fed_back',
    [([0.0, 0.0, -0.1], False), ([0.0, 0.0, 0.1], True), ([0.1, 0.0, 0.0], True)],
)
def test_a_foot_moving_into_the_ground_is_not_fed_back(base_velocity, fed_back):
    """Sliding and lifting off are fed back; moving into the surface is the surface's to stop."""
    robot = make_robot()
    qc = QuadrupedController(robot, 'daqp', contact_velocity_gain=100.0)
    T = robot.get_world_to_base_transform()
    v = np.concatenate((base_velocity, np.zeros(3)))  # the whole robot translating
    robot.set_robot_state(T, robot.get_joint_positions(), v, np.zeros(12), [0.0, 0.0, -9.81])
    assert qc.update(0.0, 0.001)
    existence = qc.contacts['FL'].existence
    _, _, _, bias = robot.world_frame_terms(robot.get_frame_id('FL_foot'))
    expected = -bias[:3] - (100.0 * np.asarray(base_velocity) if fed_back else 0.0)
    np.testing.assert_allclose(existence.lb, expected, atol=1e-9)
