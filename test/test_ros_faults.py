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
Fault injection against the real nodes.

Lockstep: every check waits on simulated time or on a condition.

Each bad input: the node stays up, its commands stay finite and within the effort limits, one log
line names the cause, and a target is reached afterwards.
"""

import time

import numpy as np
from orca_ros.ros.launch_free import ARM_Q0, free_domain_id, Procs
from orca_ros.ros.probe import Probe
import pytest
from std_srvs.srv import Trigger

NAMES = [f'joint_{i}' for i in range(7)]
EFFORT = np.array([176, 176, 100, 100, 100, 38, 38], dtype=float)


@pytest.fixture(scope='module')
def arm(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('faults')
    domain = free_domain_id()
    procs = Procs(domain, str(tmp))
    procs.start_arm('lockstep')
    probe = Probe(domain)
    try:
        probe.wait_for(lambda: probe.sim_time() > 1.0, 60, 'the controller driving the bridge')
        yield probe, procs
    finally:
        probe.close()
        procs.stop()


def reach(probe, offset, sim_seconds=3.0, frame_id='', tol=2e-3):
    """
    Send a target offset from the current end-effector pose.

    Assert it is reached within sim_seconds.
    """
    target = probe.ee_pose()  # also sets the probe's model to the current state
    target[:3, 3] += offset
    msg_pose = target
    if (
        frame_id and frame_id != 'world'
    ):  # the pose as seen from that link, resolved by the node on reception
        msg_pose = np.linalg.inv(probe.robot.get_frame_pose(frame_id)) @ target
    probe.send_target('ee', msg_pose, frame_id=frame_id, until=probe.moved_towards(target))
    t_end = probe.sim_time() + sim_seconds
    probe.wait_for(
        lambda: (
            probe.sim_time() >= t_end
            or np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3]) < tol * 0.5
        ),
        120,
        'the target',
    )
    probe.wait_sim(0.3)
    err = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
    assert err < tol, f'end effector {err * 1e3:.1f} mm from the target'
    return target


def commands_sane(probe, since):
    cmds = np.array(probe.commands[since:])
    assert len(cmds) > 0
    assert np.isfinite(cmds).all()
    assert (np.abs(cmds) <= EFFORT + 1e-9).all(), (
        f'command beyond the effort limits: {np.abs(cmds).max(0)}'
    )


def alive(procs):
    for p, _, name in procs.procs:
        assert p.poll() is None, f'{name} died:\n{procs.log(name)[-3000:]}'
    for name in ('controller', 'bridge'):
        assert 'Traceback' not in procs.log(name), procs.log(name)[-3000:]


def bad_state(names, q, v):
    return Probe.state_message(names, q, v)


def test_target_in_world_frame(arm):
    probe, procs = arm
    n0 = len(probe.commands)
    # fixed-base arm: world and base_link coincide here, so the same offset must be reached in both
    # frames
    reach(probe, [0.05, 0.05, 0.0], frame_id='world')
    reach(
        probe, [-0.05, 0.0, 0.03], frame_id='link_3'
    )  # a model link: pose expressed in that link
    commands_sane(probe, n0)
    alive(procs)


@pytest.mark.parametrize(
    'case,cause',
    [
        ('absurd', 'joint_3 position 1e+300 outside its limits'),
        ('absurd_velocity', 'joint_2 velocity 1e+150 beyond'),
        ('duplicates', "duplicate joint names ['joint_1']"),
        ('past_limit', 'joint_3 position -2.394 outside its limits'),
        ('sizes', '7 positions and 6 velocities'),
    ],
)
def test_bad_joint_states(arm, case, cause):
    probe, procs = arm
    q = np.array(ARM_Q0)
    names, v = list(NAMES), np.zeros(7)
    if case == 'absurd':
        q[3] = 1e300
    elif case == 'absurd_velocity':
        v[2] = 1e150
    elif case == 'duplicates':
        names = NAMES + ['joint_1']
        q = np.append(q, 0.3)
        v = np.zeros(8)
    elif case == 'past_limit':
        q[3] = -2.0944 - 0.3
    elif case == 'sizes':
        v = np.zeros(6)
    n0 = len(probe.commands)
    for _ in range(200):  # a burst: one line, not 200
        probe.pub_state.publish(bad_state(names, q, v))
    procs.wait_log('controller', cause)
    time.sleep(0.3)
    assert procs.log('controller').count(cause) == 1, (
        f"'{cause}' logged more than once for one burst"
    )
    probe.wait_sim(0.2)  # the lockstep loop never stalled on the bad states
    commands_sane(probe, n0)
    reach(probe, [0.0, 0.04, 0.0])
    alive(procs)


def test_target_flood_and_nan_targets(arm):
    probe, procs = arm
    n0 = len(probe.commands)
    start = probe.ee_pose()
    pub = probe.pub_target['ee']
    msg = probe.PoseStamped()
    from orca_ros.ros.common import matrix_to_pose

    matrix_to_pose(start, msg.pose)
    t0, sent = time.time(), 0
    while time.time() - t0 < 1.0:  # as fast as this process can publish (~10 kHz)
        pub.publish(msg)
        sent += 1
    nan = probe.PoseStamped()
    nan.pose.position.x = float('nan')
    nan.pose.orientation.w = 1.0
    for _ in range(50):
        pub.publish(nan)
    procs.wait_log('controller', "target for task 'ee' rejected: pose contains NaN")
    assert procs.log('controller').count('pose contains NaN') == 1
    probe.wait_sim(0.2)
    commands_sane(probe, n0)
    reach(probe, [0.03, 0.0, -0.03])
    assert sent > 1000
    alive(procs)


def test_unreachable_then_reachable_target(arm):
    probe, procs = arm
    far = probe.ee_pose()
    far[:3, 3] += [2.0, 0.0, 0.0]
    n0 = len(probe.commands)
    probe.send_target('ee', far, until=probe.moved_towards(far))
    probe.wait_sim(3.0)
    commands_sane(probe, n0)
    # back to a reachable pose near the start: reached although the arm spent 3 s stretched at its
    # limits
    target = np.eye(4)
    probe.robot.set_robot_state(np.array(ARM_Q0), np.zeros(7))
    target = probe.robot.get_frame_pose('link_7')
    target[:3, 3] += [0.05, -0.05, 0.05]
    probe.send_target('ee', target, until=probe.moved_towards(target))
    probe.wait_sim(5.0)
    err = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
    assert err < 2e-3, (
        f'after the unreachable target, the next one is missed by {err * 1e3:.1f} mm'
    )
    alive(procs)


def test_deactivate_stops_where_it_is(arm):
    probe, procs = arm
    # a reached pose well away from the posture target
    reach(probe, [0.12, -0.15, 0.08])
    at = probe.ee_pose()
    n0 = len(probe.states)
    assert probe.call(Trigger, '/orca_controller/deactivate', Trigger.Request()).success
    probe.wait_sim(2.0)
    states = probe.states[n0:]
    moved = max(np.linalg.norm(probe.ee_pose(s[1])[:3, 3] - at[:3, 3]) for s in states)
    speeds = np.abs(np.array([s[2] for s in states])).max(0)
    assert moved < 5e-3, f'end effector moved {moved * 1e3:.1f} mm after ~/deactivate'
    assert (speeds < 1.5).all(), f'joint speeds {speeds}'
    assert np.abs(probe.last_state()[2]).max() < 1e-2, 'not at rest 2 s after ~/deactivate'
    assert probe.call(Trigger, '/orca_controller/activate', Trigger.Request()).success
    probe.wait_sim(0.6)  # ramps in
    reach(probe, [-0.06, 0.1, -0.05], sim_seconds=4.0)
    alive(procs)
