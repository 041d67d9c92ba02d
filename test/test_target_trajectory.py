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
"""Jerk-limited target trajectories (Ruckig) at their edges: a target the state is already at."""

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip('ruckig')

from orca_ros.servo.target_trajectory import CartesianTrajectory  # noqa: E402,I100


def test_a_target_the_state_is_at_but_for_rounding_is_held():
    """
    Ruckig fails on a state 1e-15 m from its target, 1e-27 m/s velocities (any synchronization).

    Seen on the two-host run: the main job's first target (the pose the arm holds) was refused
    on every resend and the job timed out. Such a target is held: no trajectory, no error.
    """
    traj = CartesianTrajectory([0.25, 1.0], [1.0, 3.0], [5.0, 15.0])
    pose = np.eye(4)
    pose[:3, 3] = [-0.5366844980679278, 2.11870297759487e-17, 0.5593141423210669]
    target = pose.copy()
    target[:3, 3] = [-0.5366844980679282, 0.0, 0.5593141423210681]
    twist = np.array([-4.454685817157672e-15, -1.379382005139021e-27, 1.102592015674019e-14,
                      0.0, 0.0, 0.0])
    assert traj.start(2.0, pose, twist, np.zeros(6), target) == 0.0
    assert traj.finished(2.0)
    p, v, a = traj.sample(2.5)
    np.testing.assert_array_equal(p[:3, 3], target[:3, 3])
    assert not v.any() and not a.any()
    # a real move after it is planned as usual (the held target does not stick)
    far = target.copy()
    far[:3, 3] += [0.05, 0.0, 0.0]
    far[:3, :3] = pin.exp3(np.array([0.0, 0.0, 0.2]))
    d = traj.start(3.0, target, np.zeros(6), np.zeros(6), far)
    assert d > 0.2 and not traj.finished(3.0 + 0.5 * d)
    p, v, _ = traj.sample(3.0 + 0.5 * d)
    assert 0.0 < p[0, 3] - target[0, 3] < 0.05 and np.abs(v).max() > 0.0
    np.testing.assert_allclose(traj.sample(3.0 + d)[0], far, atol=1e-12)


LIMITS = ([0.25, 1.0], [1.0, 3.0], [5.0, 15.0])  # the Cartesian defaults of the nodes


def _at(p, rotvec=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3] = pin.exp3(np.asarray(rotvec, dtype=float))
    T[:3, 3] = p
    return T


def test_a_reference_the_servo_cannot_follow_restarts_from_the_measured_state():
    """
    The issue-22 case without ROS: the frame stuck, the target 10 m and 3 rad away, for 3 s.

    The reference never leads by more than the bound (0.2 s at the velocity limits: 5 cm,
    0.2 rad); at the bound it stays (the pull does not drop: no sawtooth); the next target then
    takes about as long as from the measured pose, not as from a reference metres away at speed.
    """
    measured = _at([0.5, 0.0, 0.5])
    far = _at([10.5, 0.0, 0.5], [0.0, 0.0, 3.0])
    leashed, runaway = CartesianTrajectory(*LIMITS), CartesianTrajectory(*LIMITS)
    for traj in (leashed, runaway):
        traj.start(0.0, measured, np.zeros(6), np.zeros(6), far)
    bound = leashed.lead
    np.testing.assert_allclose(bound, [0.05, 0.2])
    lin, ang = [], []
    for k in range(3001):
        ref = leashed.follow(1e-3 * k, measured)[0]
        lin.append(np.linalg.norm(ref[:3, 3] - measured[:3, 3]))
        ang.append(np.linalg.norm(pin.log3(measured[:3, :3].T @ ref[:3, :3])))
    lin, ang = np.array(lin), np.array(ang)
    assert lin.max() <= bound[0] + 1e-12 and ang.max() <= bound[1] + 1e-12
    assert leashed.restarts > 0 and not leashed.following(3.0, measured)
    first = np.argmax(lin >= bound[0] - 1e-9)
    assert first > 0 and lin[first:].min() > bound[0] - 1e-6
    near = _at([0.5, 0.12, 0.41])  # 15 cm
    fresh = CartesianTrajectory(*LIMITS).start(3.0, measured, np.zeros(6), np.zeros(6), near)
    after = leashed.start(3.0, *leashed.follow(3.0, measured), near)
    before = runaway.start(3.0, *runaway.sample(3.0), near)
    print(f'next target: {after:.2f} s (leashed), {before:.2f} s (runaway), {fresh:.2f} s fresh')
    # the bound's 5 cm and the cruise within it: at most the time to cover them twice over
    assert after < fresh + 2 * bound[0] / LIMITS[0][0]
    assert before > fresh + 2.0  # what it was


def test_a_servo_that_follows_never_restarts():
    """Perfect tracking, then 4 mm and 0.02 rad behind: the reference is the plain sample."""
    start, target = _at([0.5, 0.0, 0.5]), _at([0.7, 0.2, 0.3], [0.0, 0.5, 0.5])
    traj, plain = CartesianTrajectory(*LIMITS), CartesianTrajectory(*LIMITS)
    for tr in (traj, plain):
        tr.start(0.0, start, np.zeros(6), np.zeros(6), target)
    lag = _at([0.004, 0.0, 0.0], [0.0, 0.0, 0.02])
    for k in range(2500):
        t = 1e-3 * k
        ref = plain.sample(t)
        behind = ref[0] @ lag if k % 2 else ref[0]
        got = traj.follow(t, behind)
        for a, b in zip(got, ref):
            np.testing.assert_array_equal(a, b)
    assert traj.restarts == 0 and traj.following(t, plain.sample(t)[0] @ lag)


def test_a_stuck_joint_restarts_alone():
    """Three joints, the second stuck: its reference stays on the leash, the others' go on."""
    from orca_ros.servo.target_trajectory import JointTrajectory

    traj = JointTrajectory(3, [1.0, 1.0, 2.0], 2.0, 20.0)
    q0, target = np.zeros(3), np.array([1.0, 2.0, -1.5])
    traj.start(0.0, q0, np.zeros(3), np.zeros(3), target)
    np.testing.assert_allclose(traj.lead, [0.2, 0.2, 0.4])
    measured, refs = q0.copy(), []
    for k in range(4000):
        q, qd, _ = traj.follow(1e-3 * k, measured)
        refs.append(q)
        measured[[0, 2]] = q[[0, 2]]  # those follow perfectly
    refs = np.array(refs)
    assert np.abs(refs[:, 1]).max() <= 0.2 + 1e-12 and refs[-1, 1] > 0.2 - 1e-6
    assert traj.restarts > 0
    # the followers: continuous (no step beyond their speed limit) and at their targets
    steps = np.abs(np.diff(refs[:, [0, 2]], axis=0)).max(axis=0)
    assert (steps <= np.array([1.0, 2.0]) * 1e-3 + 1e-12).all(), steps
    np.testing.assert_allclose(refs[-1, [0, 2]], target[[0, 2]], atol=1e-9)


ACROSS = [[0.0, 0.5, 0.3, 0.0, 0.0, 0.0], [0.0, 0.3, -0.4, 0.5, 0.2, 0.1]]


@pytest.mark.parametrize('twist', ACROSS)
def test_a_start_with_a_velocity_across_the_path(twist):
    """
    A new target while the arm moves across the line to it (a measured velocity).

    Seen through the nodes: Ruckig failed (-101, its duration beyond its numerical limits: an
    axis with a thousandth of the limits to brake 0.3 m/s) and the target was refused. That
    velocity gets its share of the limits: planned, and the target reached.
    """
    traj = CartesianTrajectory(*LIMITS)
    start, target = _at([0.5, 0.0, 0.5]), _at([10.5, 0.0, 0.5])
    d = traj.start(0.0, start, np.array(twist), np.zeros(6), target)
    np.testing.assert_allclose(traj.sample(d)[0], target, atol=1e-9)
    np.testing.assert_allclose(traj.sample(0.0)[1][:3], twist[:3], atol=1e-12)  # continuous
