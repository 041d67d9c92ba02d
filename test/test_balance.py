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
Balance: a CoM target outside the support polygon (issue 11, item 5).

The quadruped stands in PyBullet (trunk height and orientation held by the trunk task, the CoM by a
CoM task) and gets a CoM target 30 cm sideways, far outside its feet. Without BalanceConstraint
the controller throws the CoM over the edge: QPs fail and the robot falls (measured: 1842 failed
cycles from 0.9 s, trunk on the ground). With it the CoM stops at the shrunk polygon's edge.
"""

import numpy as np
import orca_ros as orca
from orca_ros.constraint import convex_hull_2d
from orca_ros.constraint.balance_constraint import polygon_room
from orca_ros.examples.quadruped import (
    insert_standing,
    LEGS,
    make_robot,
    QuadrupedController,
    STAND_HEIGHT,
    STAND_Q,
    state_from_sim,
)
from orca_ros.sim import SimServer
import pytest


def _run(balance: bool, offset, seconds: float = 3.0):
    robot = make_robot()
    qc = QuadrupedController(robot, 'daqp')
    c = qc.controller
    qc.base.set_selection_vector([0, 0, 1, 1, 1, 1])  # trunk height and orientation
    com = c.add_task(orca.CoMTask, 'com')
    com.activate()
    c.remove_constraint('balance')  # the example's: on or off here
    if balance:
        c.add_constraint(orca.BalanceConstraint('balance')).activate()
    home = np.array([0.0, 0.0, STAND_HEIGHT])
    failures, rooms, c0 = 0, [], None
    with SimServer(time_step=0.001) as server:
        sim, by_name = insert_standing(server)
        for k in range(int(round(seconds / 0.001))):
            t = k * 0.001
            state_from_sim(robot, sim, by_name)
            if c0 is None:
                c0 = robot.get_center_of_mass()
            qc.set_base_target(home)
            com.set_desired(c0 + (offset if t >= 0.5 else 0.0))
            failures += not qc.update(t, 0.001)
            sim.set_joint_torque_command(c.get_joint_torque_command(), by_name)
            server.step()
            feet = np.array([sim.get_link_position(f'{leg}_foot')[:2] for leg in LEGS])
            rooms.append(polygon_room(feet, robot.get_center_of_mass()[:2]))
        height = sim.get_world_to_base_transform()[2, 3]
    return failures, np.array(rooms), height, robot.get_center_of_mass() - c0


def test_convex_hull_is_counter_clockwise_without_inner_points():
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.2, 0.1], [1, 0.5]], float)
    hull = convex_hull_2d(pts)
    assert sorted(map(tuple, hull)) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    x, y = hull[:, 0], hull[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == pytest.approx(1.0)  # CCW


def test_without_balance_a_com_target_outside_throws_the_robot():
    failures, rooms, height, _ = _run(False, [0.0, 0.3, 0.0])
    assert failures > 100 or height < 0.5 * STAND_HEIGHT  # the defect the constraint removes
    assert rooms.min() < 0.0


def test_balance_keeps_the_com_inside_with_its_margin():
    failures, rooms, height, moved = _run(True, [0.0, 0.3, 0.0])
    assert failures == 0
    margin = orca.BalanceConstraint('b').margin
    # the CoM stops at the shrunk polygon (PyBullet's feet roll a little: 2 mm of the 30 mm)
    assert rooms[500:].min() >= margin - 0.002
    assert rooms[-500:].max() <= margin + 0.01  # and goes as far towards the target as it may
    assert height == pytest.approx(STAND_HEIGHT, abs=0.01)  # no fall
    assert moved[1] > 0.05


def test_balance_leaves_a_target_inside_the_polygon_alone():
    f0, _, _, moved_free = _run(False, [0.0, 0.03, 0.0], seconds=2.0)
    f1, rooms, _, moved = _run(True, [0.0, 0.03, 0.0], seconds=2.0)
    assert f0 == f1 == 0
    assert rooms.min() > 0.03
    np.testing.assert_allclose(moved, moved_free, atol=1e-6)


def test_balance_from_yaml():
    """The shipped quadruped configuration's balance constraint, its settings; level damping."""
    from orca_ros.configuration.controller_builder import build_from_config, ConfigError
    import yaml

    with open(orca.share_path('config', 'quadruped_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    cons = cfg['constraints']
    assert 'balance' in cons['names'] and cons['balance']['type'] == 'balance'  # shipped on
    cons['balance'].update(margin=0.05, max_acceleration=3.0)
    cfg['lower_level_damping'] = 20.0
    setup = build_from_config(cfg)
    bal = setup.controller.get_constraint('balance')
    assert isinstance(bal, orca.BalanceConstraint)
    assert (bal.margin, bal.max_acceleration) == (0.05, 3.0)
    T = np.eye(4)
    T[2, 3] = STAND_HEIGHT
    setup.robot.set_robot_state(T, STAND_Q, np.zeros(6), np.zeros(12), [0.0, 0.0, -9.81])
    setup.controller.activate_tasks_and_constraints()
    for k in range(50):  # the contacts ramp in (0.2 s): they support once they carry a load
        assert setup.controller.update(k * 0.001, 0.001)
    assert len(bal.polygon) == 4  # the four feet
    cons['balance']['margin'] = -1.0
    with pytest.raises(ConfigError, match="constraint 'balance': margin"):
        build_from_config(cfg)


def test_a_bilateral_contact_supports_too():
    """A welded foot (BilateralContact, no normal-force bound) counts as one support point."""
    robot = make_robot()
    c = orca.Controller('c', robot)
    c.add_constraint(orca.BilateralContact('FL_weld', 'FL_foot'))
    for leg in ('FR', 'HL', 'HR'):
        c.add_constraint(orca.Contact(f'{leg}_contact', f'{leg}_foot'))
    bal = c.add_constraint(orca.BalanceConstraint('balance'))
    c.add_task(orca.CoMTask, 'com')
    for o in c.get_tasks() + c.get_constraints():
        o.set_ramp_duration(0.0)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 0.001)
    feet = np.array([robot.get_frame_pose(f'{leg}_foot')[:2, 3] for leg in LEGS])
    assert sorted(map(tuple, bal.polygon.round(6))) == sorted(map(tuple, feet.round(6)))


def test_the_kernels_hull_is_the_references_on_awkward_point_sets(rng):
    """Duplicates, collinear points, inner points, fewer than three: the same vertices in order."""
    from orca_ros.constraint.balance_kernel import convex_hull

    sets = [rng.normal(0.0, 0.2, (n, 2)) for n in (1, 2, 3, 4, 8, 16) for _ in range(20)]
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    sets += [square, np.vstack([square, square]), np.vstack([square, [[0.5, 0.5], [0.5, 0.0]]]),
             np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), np.array([[0.3, 0.1]] * 4),
             square + 1e-13 * rng.normal(size=square.shape)]
    for points in sets:
        pts, hull = np.zeros((len(points), 2)), np.zeros((2 * len(points), 2))
        k = convex_hull(np.ascontiguousarray(points), pts, hull)
        assert np.array_equal(hull[:k], convex_hull_2d(points)), points


def test_the_kernels_rows_are_the_references_on_the_quadruped():
    """
    The balance rows by kernel (the compiled cycle's) against numpy's, at 1300 random states.

    The quadruped example's controller, compiled and not, fed the same states: four feet, then
    three (a contact off, once its load has ramped out), then two (no polygon: every row
    relaxed). Rows equal to round-off.
    """
    import pinocchio as pin

    pair = []
    for compiled in (True, False):
        robot = make_robot()
        qc = QuadrupedController(robot, 'daqp')
        qc.controller.compiled = compiled
        pair.append(qc)
    rng = np.random.default_rng(3)
    model = pair[0].robot.model
    q0 = pin.neutral(model)
    q0[2], q0[7:] = STAND_HEIGHT, STAND_Q
    worst, seen = 0.0, set()  # and the polygons' edge counts (0: none)
    for k in range(1300):
        q = q0.copy()
        q[:3] += rng.normal(0.0, 0.01, 3)
        q[7:] += rng.normal(0.0, 0.05, model.nq - 7)
        v = rng.normal(0.0, 0.2, model.nv)
        for qc in pair:
            qc.robot.set_configuration(q, v)
            if k == 50:
                qc.contacts['FL'].deactivate()
            if k == 650:
                qc.contacts['HR'].deactivate()
            qc.set_base_target([0.0, 0.0, STAND_HEIGHT])
            qc.update(k * 1e-3, 1e-3)
        b1, b2 = (qc.controller.get_constraint('balance') for qc in pair)
        if k == 0:
            assert b1._kernel is not None and b2._kernel is None
        np.testing.assert_array_equal(b1.polygon, b2.polygon)
        seen.add(len(b2.polygon) if len(b2.polygon) >= 3 else 0)
        np.testing.assert_allclose(b1.C, b2.C, rtol=0.0, atol=1e-14)
        np.testing.assert_array_equal(np.isinf(b1.ub), np.isinf(b2.ub))
        finite = np.isfinite(b2.ub)
        scale = np.maximum(1.0, np.abs(b2.ub[finite]))
        worst = max(worst, (np.abs(b1.ub[finite] - b2.ub[finite]) / scale).max(initial=0.0))
        np.testing.assert_array_equal(b1.lb, b2.lb)
    print(f'bounds differ by {worst:.1e} (relative); polygons of {sorted(seen)} edges')
    assert seen == {0, 3, 4}
    assert worst < 1e-12
