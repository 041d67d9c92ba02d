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
An obstacle known by sparse poses (a perception's): the torques between poses.

The shipped lwr configuration plus a collision constraint with its defaults, on the rigid-body
model, in process: the arm holds its pose while a 5 cm ball comes at its hand from the side at
0.3 m/s, passes 10 cm beyond where the hand was and stops dead (as test_ros_obstacles.py's, whose
probe sends a pose at every step it sees). Here the poses come every ``period`` (give or take a
jitter) and reach the controller ``latency`` after their instant, each with the velocity the node
derives from the poses (ObstacleVelocity), carried on from its instant by the constraint.
"""

import numpy as np
import orca_ros as orca
from orca_ros.configuration.controller_builder import build_from_config
from orca_ros.constraint.obstacle_velocity import ObstacleVelocity
from orca_ros.examples.common import integrate
import pytest
import yaml

DT, T0, T_END = 1e-3, 1.0, 2.8  # the ball starts at T0; the run ends at T_END [s]
RADIUS, SPEED, TRAVEL = 0.05, 0.3, 0.35


def _ball_run(period, latency, jitter, seed, **collision):
    """
    Run the ball at the holding arm, its poses every ``period`` cycles, ``latency`` late.

    ``period`` give or take ``jitter`` [cycles]. Return the torque steps per cycle from T0 on,
    and the QP failures.
    """
    robot, c = _lwr(**collision)
    col = c.get_constraint('collision')
    q, v = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]), np.zeros(7)
    robot.set_robot_state(q, v)
    hand0 = robot.get_frame_pose('link_7')
    c.get_task('ee').servo_controller().set_desired(hand0.copy())
    c.activate_tasks_and_constraints()
    start = hand0[:3, 3] - [0.0, 0.25, 0.0]
    rng, velocities = np.random.default_rng(seed), ObstacleVelocity()
    poses, next_pose, added = [], T0, False  # poses: (arrival cycle, instant, position)
    taus, failures = [], 0
    for k in range(int(round(T_END / DT))):
        t = k * DT
        if t >= next_pose - 1e-9:
            poses.append((k + latency, t, start + [0.0, min(SPEED * (t - T0), TRAVEL), 0.0]))
            next_pose = t + (period + rng.integers(-jitter, jitter + 1)) * DT
        while poses and poses[0][0] <= k:
            _, at, centre = poses.pop(0)
            pose = np.eye(4)
            pose[:3, 3] = centre
            velocity = velocities.observe('ball', centre, at)
            if added:
                col.move_obstacle('ball', pose, None, velocity, at)
            else:
                col.add_obstacle('ball', 'sphere', [RADIUS], pose)
                added = True
        robot.set_robot_state(q, v)
        failures += not c.update(t, DT)
        taus.append(c.get_joint_torque_command().copy())
        q, v = integrate(robot, q, v, taus[-1], DT)
    steps = np.abs(np.diff(np.array(taus), axis=0)).max(axis=1)
    return steps[int(round(T0 / DT)):], failures


def _lwr(compiled=True, hold=True, **collision):
    """Return the shipped lwr configuration plus a collision constraint: robot, controller."""
    with open(orca.share_path('config', 'lwr_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    cfg['constraints']['names'] = cfg['constraints']['names'] + ['collision']
    cfg['constraints']['collision'] = {'type': 'collision_avoidance', **collision}
    cfg['compiled'] = compiled
    setup = build_from_config(cfg)
    if not hold:
        setup.controller.get_constraint('collision').settings[4] = np.inf  # no row held
    return setup.robot, setup.controller


def _pushed_then_freed(*arms):
    """
    Push the arm with the ball, then take the ball away at once; return the torques, arm by arm.

    The ball comes at the hand (a pose each cycle, with its velocity) and stops where the hand
    was: the arm rests against it, its task pulling into it. At 3 s a pose puts it 30 cm up (a
    detection corrected). Each arm (robot, controller) is given the first one's states.
    """
    q, v = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]), np.zeros(7)
    for robot, c in arms:
        robot.set_robot_state(q, v)
        hand0 = robot.get_frame_pose('link_7')
        c.get_task('ee').servo_controller().set_desired(hand0.copy())
        c.activate_tasks_and_constraints()
    start = hand0[:3, 3] - [0.0, 0.25, 0.0]
    taus = [[] for _ in arms]
    for k in range(4000):
        t = k * DT
        travel = min(SPEED * (t - T0), 0.25)
        pose, velocity = np.eye(4), np.array([0.0, SPEED if travel < 0.25 else 0.0, 0.0])
        pose[:3, 3] = start + [0.0, travel, 0.0]
        if t >= 3.0:
            pose[2, 3] += 0.3
            velocity[:] = 0.0
        for (robot, c), out in zip(arms, taus):
            col = c.get_constraint('collision')
            if k == int(round(T0 / DT)):
                col.add_obstacle('ball', 'sphere', [RADIUS], pose)
            elif t > T0:
                col.move_obstacle('ball', pose, None, velocity, t)
            robot.set_robot_state(q, v)
            assert c.update(t, DT), c.get_return_code()
            out.append(c.get_joint_torque_command().copy())
        q, v = integrate(arms[0][0], q, v, taus[0][-1], DT)
    return [np.array(x) for x in taus]


def test_rows_of_an_obstacle_that_moves_off_at_once_relax_away():
    """
    Its pairs leave the rows with bounds that bind: each keeps its last row, relaxing.

    1.88 Nm per cycle at most through the jump; dropped at once (no row held), the rows let the
    torques jump 154 Nm in one cycle, to joint 1's limit. The same holds for a pair the arm is
    pushed out of the influence distance of (an obstacle that came too close): 175 Nm in one
    cycle with poses of a ball every 100 ms, before.
    """
    jump = int(round(3.0 / DT))
    arm = _lwr()
    held, = _pushed_then_freed(arm)
    dropped, = _pushed_then_freed(_lwr(hold=False))
    steps = np.abs(np.diff(held, axis=0)).max(axis=1)
    at_once = np.abs(np.diff(dropped, axis=0)).max(axis=1)[jump - 1:].max()
    print(f'largest step: before the jump {steps[1000:jump - 1].max():.2f} Nm, through it '
          f'{steps[jump - 1:].max():.2f} Nm; no row held {at_once:.1f} Nm')
    assert at_once > 50.0  # the run does take rows off binding bounds
    assert steps[jump - 1:].max() <= 2.0
    # the ball's rows all let go in the end (1 s on)
    assert not [p for p in arm[1].get_constraint('collision').last_pairs if 'ball' in p[1]]


def test_rows_held_by_kernel_equal_the_reference():
    """The compiled cycle's kernels against the Python path, on the same states, each cycle."""
    compiled, reference = _pushed_then_freed(_lwr(), _lwr(compiled=False))
    scale = np.maximum(1.0, np.abs(reference).max(axis=1))
    assert (np.abs(compiled - reference).max(axis=1) / scale).max() < 1e-9


@pytest.mark.parametrize('period, max_extrapolation, bound', [
    (33, None, 2.0),  # a 30 Hz perception: the defaults
    (100, 0.2, 6.0),  # 10 Hz: carried on over its period plus latency
], ids=['30Hz_defaults', '10Hz_max_extrapolation_0.2'])
def test_sparse_late_poses_are_carried_on_along_the_ball_s_velocity(
    period, max_extrapolation, bound
):
    """
    Poses 30 ms late, their period +-10 ms: the ball carried on between them, the torques smooth.

    Measured (three seeds): 30 Hz, defaults, 1.6-1.7 Nm per cycle at most (the arm's own fast
    return; poses each cycle: 1.6 too); 10 Hz, 3.3-5.3 Nm with max_extrapolation 0.2 s against
    15-17 at the default 0.1 (the ball standing still past 0.1 s, then jumping), and 23-53 when
    poses more than 0.1 s apart gave no velocity (before VELOCITY_WINDOW).
    """
    extra = {} if max_extrapolation is None else {'max_extrapolation': max_extrapolation}
    worst = []
    for seed in range(3):
        steps, failures = _ball_run(period, 30, 10, seed, **extra)
        assert failures == 0
        worst.append(steps.max())
    print(f'{period} ms poses: largest steps {np.round(worst, 2)} Nm')
    assert max(worst) <= bound


def test_velocity_from_poses_within_the_window_and_of_one_clock():
    track = ObstacleVelocity()
    assert track.observe('b', [0.0, 0.0, 0.0], 1.0) is None  # the first pose
    assert np.allclose(track.observe('b', [0.0, 0.03, 0.0], 1.1), [0.0, 0.3, 0.0])  # 10 Hz
    assert np.allclose(track.observe('b', [0.0, 0.03, 0.0], 1.1), [0.0, 0.3, 0.0])  # same instant
    assert track.observe('b', [0.0, 0.0, 0.0], 1.05) is None  # older: not recorded
    assert np.allclose(track.observe('b', [0.0, 0.06, 0.0], 1.3), [0.0, 0.15, 0.0])
    assert track.observe('b', [0.0, 0.06, 0.0], 1.6) is None  # 0.3 s apart: beyond the window
    assert track.observe('b', [0.0, 0.07, 0.0], 1.65, clock='receipt') is None  # another clock
    track.forget('b')
    assert track.observe('b', [0.0, 0.08, 0.0], 1.7, clock='receipt') is None


def _ball_pair(col):
    """Return (row, distance) of the ball's closest pair in the last cycle's rows, or None."""
    rows = [(i, d) for i, (_, b, d) in enumerate(col.last_pairs) if 'ball' in b]
    return min(rows, key=lambda r: r[1]) if rows else None


@pytest.mark.parametrize('compiled', [True, False], ids=['compiled', 'reference'])
def test_a_pair_creeping_onto_the_safety_distance_tightens_its_bound_at_a_bounded_rate(compiled):
    """
    The braking margin's term tightens a row at A / horizon per second at most.

    Near the limit its slope in the distance is A / (h v / 2): at a closing speed of 10 um/s,
    10 m/s^2 per micrometre. The ball creeps onto the safety distance 0.2 um per cycle while its
    velocity says 10 um/s (as the lwr's link 6 crept onto the ball in test_ros_obstacles.py, its
    simulator integrating ahead of the constraint's model): the row's bound rises by at most
    A / h dt per cycle, where it jumped 2-3 m/s^2 (up to 9.3 Nm in one cycle through the nodes).
    What viability and the horizon ask applies at once: the bound never falls below them.
    """
    robot, c = _lwr(compiled)
    col = c.get_constraint('collision')
    q, v = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]), np.zeros(7)
    robot.set_robot_state(q, v)
    c.get_task('ee').servo_controller().set_desired(robot.get_frame_pose('link_7'))
    c.activate_tasks_and_constraints()
    pose = np.eye(4)
    pose[:3, 3] = robot.get_frame_pose('link_7')[:3, 3] - [0.0, 0.1, 0.0]
    col.add_obstacle('ball', 'sphere', [RADIUS], pose)
    safety, A, h = col.safety_distance, col.max_deceleration, col.horizon
    relax = A / h * DT
    speed, creep = 1e-5, 0.2e-6  # the velocity said, the distance lost per cycle [m/s, m]
    t = 0.0

    def cycle(y):
        nonlocal t
        pose[1, 3] = y
        col.move_obstacle('ball', pose, None, np.array([0.0, speed, 0.0]), t)
        robot.set_robot_state(q, v)
        assert c.update(t, DT), c.get_return_code()
        t += DT
        return _ball_pair(col)

    y = pose[1, 3]
    for _ in range(3):  # the ball 20 um outside the safety distance (its y per distance lost)
        d0 = cycle(y)[1]
        slope = (d0 - cycle(y + 1e-4)[1]) / 1e-4
        y += (d0 - safety - 20e-6) / slope
    for _ in range(20):  # settled there
        cycle(y)
    rises, prev = [], None
    while True:
        y += creep / slope
        row, d = cycle(y)
        lb = float(col.lb[row])
        if prev is not None:
            rises.append(lb - prev)
        prev = lb
        if d - safety < 0.02e-6:
            break
    print(f'{len(rises)} cycles from 20 um to the safety distance: the bound rose by at most '
          f'{max(rises):.4f} m/s^2 per cycle (A / h dt = {relax:.3f})')
    assert len(rises) > 50
    assert max(rises) <= relax + 1e-9


def test_an_obstacle_deeper_than_max_depth_into_the_arm_is_refused_and_nothing_changes():
    """
    Added or moved more than max_depth into a moving link: ValueError naming the link and depth.

    The shipped lwr with a collision constraint (``max_depth`` from the YAML: 5 cm here). A ball
    of 100 m round the base is refused; so is a 3 cm ball put on the hand's frame origin (the
    wrist's joint, inside link_6's body: 90 mm deep). The same ball 10 cm beside the hand is
    taken, its move back onto the hand refused, leaving it where it was; a move to 5 cm beside
    it (less deep than 5 cm) taken.
    """
    robot, c = _lwr(max_depth=0.05)
    col = c.get_constraint('collision')
    q = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0])
    robot.set_robot_state(q, np.zeros(7))
    c.activate_tasks_and_constraints()
    assert c.update(0.0, DT)
    assert col.max_depth == 0.05
    hand = robot.get_frame_pose('link_7')
    with pytest.raises(ValueError, match=r"it would go 9\d{4} mm into the robot \('link_\d'\), "
                       r'deeper than max_depth \(50 mm\)'):
        col.add_obstacle('huge', 'sphere', [100.0], np.eye(4))
    on_hand = hand.copy()
    with pytest.raises(ValueError, match=r"into the robot \('link_\d'\)"):
        col.add_obstacle('ball', 'sphere', [0.03], on_hand)
    assert col.obstacle_names() == []
    beside = hand.copy()
    beside[:3, 3] += [0.0, 0.1, 0.0]
    col.add_obstacle('ball', 'sphere', [0.03], beside)
    with pytest.raises(ValueError, match=r"into the robot \('link_\d'\)"):
        col.move_obstacle('ball', on_hand)
    index = col.geometry.obstacles['ball']
    placed = col.geometry.geom_model.geometryObjects[index].placement
    assert np.allclose(placed.translation, beside[:3, 3], atol=0.0)
    nearer = hand.copy()
    nearer[:3, 3] += [0.0, 0.05, 0.0]
    col.move_obstacle('ball', nearer)
    assert np.allclose(col.geometry.geom_model.geometryObjects[index].placement.translation,
                       nearer[:3, 3], atol=0.0)
    assert c.update(DT, DT)
