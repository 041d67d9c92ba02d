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
A quadruped nobody tuned for on joint impedance drives, through the nodes (issue 39).

Go1 of example-robot-data with the shipped config/quadruped_controller.yaml, only its names
changed (test_ros_quadruped_start.other_quadruped) and ``command_interface``: the bridge's drives
run their law tau_ff + K_p (q_r - q) + K_d (v_r - v) at every 0.5 ms simulation step (2 kHz), the
controller at 1 kHz (one command per two steps) and at 500 Hz (per four). Lockstep, the probe in
the loop: the trunk's target is streamed along a 3 cm sway, then the trunk is pushed sideways with
100 N for 0.1 s (the bridge's ``~/external_force``), each at its instant of simulated time. The
same scenario on effort drives is the yardstick: the trunk's error within 2x of it.
"""

import re

import numpy as np
import orca_ros as orca
from orca_ros.examples.quadruped import sinusoid
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest
from test_ros_quadruped_start import _tilt, _vector, GAP, other_quadruped

RELAY = '/probe/relayed_commands'
STEP = 0.0005  # the simulation's step: the drives' loop at 2 kHz
SWAY, SWAY_PERIOD = 0.03, 2.0  # one period of a 3 cm sway (fading in and out)
PUSH_AT, PUSH, PUSH_FOR = 2.1, 100.0, 0.1  # s after the sway's start, N (along y), s
END = 3.5  # s after the sway's start
PUSHED = re.compile(r"external force \[([^\]]*)\] N on '(\w+)' from t = (\S+) s")


def _gains(robot_inertia, frequency: float = 10.0):
    """
    Return the joint impedance's gains: each joint critically damped at ``frequency`` Hz.

    m_i = 1 / (M^-1)_ii at the standing pose (the joint's inertia with the others free):
    K_p = m_i (2 pi f)^2, K_d = 2 m_i (2 pi f), as docs/command_interfaces.md picks them.
    """
    w = 2 * np.pi * frequency
    return robot_inertia * w * w, 2 * robot_inertia * w


def _joint_inertia(quad):
    """Return each joint's inertia with the others free at the standing pose, and the joints."""
    robot = orca.RobotModel()
    robot.load_model_from_file(quad.urdf, floating_base=True)
    robot.set_configuration(quad.q, np.zeros(robot.model.nv))
    return 1.0 / np.diag(np.linalg.inv(robot.get_mass_matrix()))[6:], robot.get_joint_names()


def _run(tmp_path, example_robot_urdf, interface: str, period: float):
    """Stand, sway, push; return the trunk's samples (s after the sway's start, position, tilt)."""
    tmp_path.mkdir()
    quad, params = other_quadruped('go1')(example_robot_urdf, tmp_path)
    inertia, joints = _joint_inertia(quad)
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'command_interface:={interface}')
    procs.start(
        'orca_ros.ros.pybullet_bridge',
        '-p', 'mode:=lockstep',
        '-p', f'urdf_path:={quad.urdf}',
        '-p', 'floating_base:=true',
        '-p', f'joints:={joints}',
        '-p', f'base_position:={_vector(quad.home + [0.0, 0.0, GAP])}',
        '-p', f'base_orientation:={_vector(quad.q[3:7])}',
        '-p', f'initial_positions:={_vector(quad.joints)}',
        '-p', f'time_step:={STEP}',
        '-p', f'control_period:={period}',
        *both,
        name='bridge',
    )
    gains = ()
    if interface == 'joint_impedance':
        kp, kd = _gains(inertia)
        gains = ('-p', f'joint_stiffness:={_vector(kp)}', '-p', f'joint_damping:={_vector(kd)}')
    procs.start(
        'orca_ros.ros.controller_node',
        '--params-file', params,
        '-p', 'trigger:=joint_state',
        '-p', f'update_rate:={1.0 / period}',
        '-p', f'command_topic:={RELAY}',
        *both, *gains,
        name='controller',
    )
    probe = Probe(domain, joints=joints, relay_from=RELAY)
    from geometry_msgs.msg import WrenchStamped

    push = probe.node.create_publisher(WrenchStamped, '/pybullet_bridge/external_force', 10)

    def shove(force):
        m = WrenchStamped()
        m.header.frame_id = quad.trunk
        m.wrench.force.y = float(force)
        push.publish(m)

    home = quad.home
    try:
        probe.wait_for(lambda: probe.sim_time() > 0.5, 300, 'the controller standing Go1')
        probe.send_target_point('base', home)  # the publisher, matched before the stream
        t0 = probe.sim_time()
        pushing = []

        def stream(answered):
            # the instant the command being relayed leads to: one period after the state it
            # answers; its target and the push in effect sent before it
            s = answered + period - t0
            y, vy, ay = sinusoid(min(s, SWAY_PERIOD), SWAY, SWAY_PERIOD, SWAY_PERIOD)
            probe.send_target_point('base', home + [0, y, 0], (0, vy, 0), (0, ay, 0))
            on = PUSH_AT <= s < PUSH_AT + PUSH_FOR
            if on != bool(pushing and pushing[-1]):
                shove(PUSH if on else 0.0)
                pushing.append(on)

        probe.relay_hook = stream
        probe.wait_for(lambda: probe.sim_time() > t0 + END, 600, 'the sway and the push')
        probe.relay_hook = None
        assert not probe.relay_errors, probe.relay_errors
        with probe.lock:
            odom = list(probe.odom)
        failures = int(probe.diagnostics.get('qp_failures', '-1'))
        log, bridge_log = procs.log('controller'), procs.log('bridge')
    finally:
        probe.close()
        procs.stop()
    samples = [(t - t0, p, _tilt(o)) for t, p, o in odom if t0 < t <= t0 + END]
    applied = [(round(float(t) - t0, 4), f) for f, _, t in PUSHED.findall(bridge_log)]
    return samples, failures, log, bridge_log, applied, home


@pytest.mark.parametrize('period', [0.001, 0.002])
def test_go1_on_joint_impedance_stands_sways_and_takes_a_push(
    tmp_path, example_robot_urdf, period
):
    """
    On joint impedance drives Go1 tracks and recovers as on effort drives, within 2x.

    The trunk's error: rms from the streamed sway's reference over the sway, and its largest
    distance from the standing target after the push. No fall (tilt < 0.3 rad, trunk above half
    its height), no failed cycle, no safe command.
    """
    result = {}
    for interface in ('effort', 'joint_impedance'):
        samples, failures, log, bridge_log, applied, home = _run(
            tmp_path / interface, example_robot_urdf, interface, period)
        s = np.array([x[0] for x in samples])
        p = np.array([x[1] for x in samples])
        tilt = max(x[2] for x in samples)
        ref = np.array([home + [0, sinusoid(min(t, SWAY_PERIOD), SWAY, SWAY_PERIOD,
                                            SWAY_PERIOD)[0], 0] for t in s])
        sway = s < PUSH_AT
        rms = np.sqrt(np.mean(np.sum((p[sway] - ref[sway]) ** 2, axis=1)))
        after = np.linalg.norm(p[~sway] - home, axis=1)
        result[interface] = rms, after.max(), after[-1]
        print(f'Go1, {interface}, controller at {1 / period:.0f} Hz, drives at {1 / STEP:.0f} '
              f'Hz: sway rms {rms * 1e3:.3f} mm, pushed {after.max() * 1e3:.1f} mm away, '
              f'{after[-1] * 1e3:.2f} mm at the end; tilt {tilt:.3f} rad, {failures} failed '
              f'cycles; pushes {applied}')
        assert np.ptp(p[sway, 1]) > 0.95 * np.ptp(ref[sway, 1])  # it swayed as asked
        assert len(applied) == 1 and abs(applied[0][0] - PUSH_AT) < 0.01, bridge_log[-3000:]
        assert tilt < 0.3 and p[:, 2].min() > 0.5 * home[2]  # no fall
        assert failures == 0, log[-3000:]
        assert 'safe command' not in log, log[-3000:]
    eff, imp = result['effort'], result['joint_impedance']
    assert imp[0] <= 2 * eff[0]  # the sway
    assert imp[1] <= 2 * eff[1]  # the push
    assert imp[2] <= max(2 * eff[2], 1e-3)  # back at the target (1 mm: the contacts' give)
