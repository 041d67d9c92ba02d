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
"""Bad input on the wire: clear log lines, safe finite commands, nodes stay up and recover."""

import time

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest
from std_msgs.msg import Float64MultiArray

NAMES = [f'joint_{i}' for i in range(7)]
Q0 = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0])


def _state(names=NAMES, q=Q0, v=np.zeros(7)):
    return Probe.state_message(names, q, v)


def test_controller_survives_bad_states_and_targets(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start(
        'orca_ros.ros.controller_node',
        '--params-file',
        orca.share_path('config', 'lwr_controller.yaml'),
        '-p',
        'update_rate:=200.0',
        name='controller',
    )
    probe = Probe(domain)
    try:
        pub = probe.pub_state

        def until(make, predicate, what):
            probe.publish_until(lambda: pub.publish(make()), predicate, what, period=0.005)

        procs.wait_log('controller', 'orca_controller: 7 joints')
        time.sleep(1.0)
        assert probe.commands == [], 'no command may be sent before the first joint state'
        # valid states, with an extra joint the controller does not know: ignored
        extra = NAMES + ['gripper_joint']
        robot = orca.RobotModel()
        robot.load_model_from_file(orca.default_urdf_path())
        robot.set_robot_state(Q0, np.zeros(7))
        g = robot.get_joint_gravity_torques()
        # at rest, holding its pose, the arm needs its gravity torques (once the ramps are done)
        until(
            lambda: _state(extra, np.append(Q0, 0.3), np.zeros(8)),
            lambda: len(probe.commands) > 50 and np.abs(probe.commands[-1] - g).max() < 0.5,
            'commands holding the arm',
        )
        assert 'first joint state received' in procs.log('controller')

        # NaN in the state: rejected, and once the good state is too old the safe command takes
        # over
        nan_q = Q0.copy()
        nan_q[3] = np.nan
        n0 = len(probe.commands)
        until(
            lambda: _state(q=nan_q),
            lambda: 'safe command: joint_states stale' in procs.log('controller'),
            'the stale-state fallback',
        )
        assert (
            "joint_states rejected: NaN or infinite position/velocity of ['joint_3']"
            in procs.log('controller')
        )
        # a missing joint
        until(
            lambda: _state(NAMES[:-1], Q0[:-1], np.zeros(6)),
            lambda: "missing joints ['joint_6']" in procs.log('controller'),
            'the missing-joint line',
        )
        # a target in an unknown frame
        T = np.eye(4)
        T[:3, 3] = [0.4, 0.0, 0.5]
        probe.send_target(
            'ee',
            T,
            frame_id='no_such_link',
            until=lambda: "unknown frame 'no_such_link'" in procs.log('controller'),
        )
        probe.wait_for(
            lambda: len(probe.commands) > n0 + 20, 30, 'commands while the state is bad'
        )
        during = np.array(probe.commands[n0:])
        assert np.all(np.isfinite(during))
        # the safe command is gravity (+ no damping: velocity unknown while stale): the arm is held
        np.testing.assert_allclose(during[-1], g, atol=0.5)
        # states stop altogether: still finite commands, and the node stays up
        n1 = len(probe.commands)
        probe.wait_for(lambda: len(probe.commands) > n1 + 20, 30, 'commands without states')
        assert np.all(np.isfinite(np.array(probe.commands[n1:])))
        # good data again: control resumes
        until(lambda: _state(), lambda: 'recovered from' in procs.log('controller'), 'recovery')
        until(
            lambda: _state(),
            lambda: np.abs(probe.commands[-1] - g).max() < 0.5,
            'the gravity hold after recovery',
        )
        assert procs.procs[0][0].poll() is None, 'the controller must still be running'
        assert 'Traceback' not in procs.log('controller')
    finally:
        probe.close()
        procs.stop()


@pytest.mark.parametrize('simulator', ['pybullet', 'mujoco'])
def test_bridge_rejects_bad_commands(tmp_path, simulator):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start(
        f'orca_ros.ros.{simulator}_bridge',
        '-p',
        'mode:=free_running',
        '-p',
        'rate:=200.0',
        '-p',
        'gravity_compensation:=true',
        '-p',
        'initial_positions:=[0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]',
        name='bridge',
    )
    probe = Probe(domain)
    try:
        pub = probe.pub_command
        probe.wait_for(lambda: len(probe.states) > 20, 30, 'joint states from the bridge')
        for data in ([1.0, 2.0], [0.0, 0.0, float('nan'), 0.0, 0.0, 0.0, 0.0]):
            m = Float64MultiArray()
            m.data = data
            for _ in range(5):
                pub.publish(m)
                time.sleep(0.05)
        procs.wait_log('bridge', 'rejected effort command (2 values for 7 joints)')
        procs.wait_log('bridge', 'rejected effort command (non-finite values)')
        n = len(probe.states)
        probe.wait_for(lambda: len(probe.states) > n + 20, 30, 'the bridge to keep publishing')
        # with emulated gravity compensation and zero command the arm stays where it is
        np.testing.assert_allclose(probe.last_state()[1], Q0, atol=1e-3)
        assert 'Traceback' not in procs.log('bridge')
    finally:
        probe.close()
        procs.stop()


def test_lockstep_controller_answers_a_repeated_state_once_more(tmp_path):
    """
    Answer a repeated lockstep state with the command of that instant.

    A lockstep simulator whose command was lost (sent before discovery matched it) announces the
    same state again: the controller sends the command of that instant again instead of waiting
    forever (it does not compute a second step).
    """
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm_controller('lockstep')
    probe = Probe(domain)
    try:
        msg = _state()
        msg.header.stamp.sec = 3
        probe.publish_until(
            lambda: probe.pub_state.publish(msg),
            lambda: len(probe.commands) >= 5,
            'commands answering the same state',
            period=0.05,
        )
        cmds = np.array(probe.commands)
        np.testing.assert_array_equal(cmds, np.repeat(cmds[:1], len(cmds), axis=0))
        assert np.all(np.isfinite(cmds))
        # a new instant is computed (and only then)
        msg.header.stamp.sec = 4
        n = len(probe.commands)
        probe.publish_until(
            lambda: probe.pub_state.publish(msg), lambda: len(probe.commands) > n, 'a new command'
        )
        assert 'Traceback' not in procs.log('controller')
    finally:
        probe.close()
        procs.stop()
