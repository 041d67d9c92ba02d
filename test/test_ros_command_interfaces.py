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
Command interfaces through the nodes: the shipped lwr configuration, only the interface changed.

The controller and the bridge both take ``command_interface``; the bridge's drives (position or
velocity servos, joint impedance with the gains of each command) run at the simulator's rate.
Lockstep, a configured target 29 cm from the hand.
"""

import json

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import ARM_Q0, free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest

TARGET = [-0.45, -0.2, 0.45]
RPY = [3.14159, -0.84159, 3.14159]


def _impedance_gains(frequency: float = 10.0):
    """
    Return the joint impedance's gains as node arguments: each joint critically damped at f Hz.

    On its inertia with the other joints free at the start posture, m_i = 1 / (M^-1)_ii (one
    gain for all, 300 Nm/rad and 10 Nm s/rad, made the lwr's last joint, 2.3e-4 kg m^2, unstable
    in a 1 ms simulation step: K_d dt / m = 43).
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(np.array(ARM_Q0, dtype=float), np.zeros(7))
    m = 1.0 / np.diag(np.linalg.inv(robot.get_mass_matrix()))
    w = 2 * np.pi * frequency
    return ('-p', f'joint_stiffness:={(m * w * w).tolist()}',
            '-p', f'joint_damping:={(2 * m * w).tolist()}')


GAINS = _impedance_gains()


def _reach(tmp_path, interface: str, simulator: str = 'pybullet', duration: float = 3.0,
           both_args=(), bridge_args=(), controller_args=()):
    """Run to ``duration`` s of simulated time; return the final hand position, states, logs."""
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'command_interface:={interface}', *both_args)
    procs.start_arm(
        'lockstep',
        simulator=simulator,
        controller_args=('-p', f'tasks.ee.target_position:={TARGET}',
                         '-p', f'tasks.ee.target_rpy:={RPY}', *both,
                         *(GAINS if interface == 'joint_impedance' else ()), *controller_args),
        bridge_args=('-p', f'stop_time:={duration}', '-p', 'start_paused:=true', *both,
                     *bridge_args),
    )
    probe = Probe(domain)
    try:
        # the probe listening before the first step: it records the run from its start
        probe.wait_for(lambda: probe.sim_time() >= 0.0, 120, "the simulator's first state")
        probe.unpause(simulator=simulator)
        probe.wait_for(lambda: probe.sim_time() >= duration - 1e-9, 120, 'the end of the run')
        with probe.lock:
            states = list(probe.states)
        logs = procs.log('controller'), procs.log('bridge')
    finally:
        probe.close()
        procs.stop()
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(states[-1][1], np.zeros(7))
    return robot.get_frame_pose('link_7')[:3, 3], states, robot, logs


@pytest.mark.parametrize('interface, simulator', [
    ('position', 'pybullet'), ('velocity', 'pybullet'), ('position_velocity', 'pybullet'),
    ('joint_impedance', 'pybullet'), ('position', 'mujoco'), ('joint_impedance', 'mujoco'),
])
def test_each_interface_reaches_the_target_within_the_joint_limits(tmp_path, interface,
                                                                   simulator):
    """
    Within 1 mm of the target after 3 s, as with efforts; positions and speeds within the limits.

    Measured on the simulated joints (the bridge's joint_states) from the first step on, every
    state the probe recorded; on MuJoCo too (its drives the same model: the same code before
    each of its steps).
    """
    hand, states, robot, (log, bridge_log) = _reach(tmp_path, interface, simulator)
    error = np.linalg.norm(hand - TARGET)
    lo, hi = robot.get_joint_position_limits()
    vmax = robot.get_joint_velocity_limits()
    q = np.array([s[1] for s in states])
    v = np.array([s[2] for s in states])
    speed = (np.abs(v) / vmax).max()
    room = min((q - lo).min(), (hi - q).min())
    assert states[0][0] <= 1e-3, f'the probe missed the start: first state at {states[0][0]} s'
    print(f'{interface} ({simulator}): {error * 1e3:.3f} mm from the target; fastest joint at '
          f'{speed:.2f} of its limit; least room to a position limit {room:.3f}')
    assert error < 1e-3
    assert (q >= lo).all() and (q <= hi).all()
    assert speed <= 1.0
    assert 'safe command' not in log, log[-2000:]
    assert 'rejected' not in bridge_log, bridge_log[-2000:]


@pytest.mark.parametrize('interface', ['position_velocity', 'joint_impedance'])
def test_joint_state_commands_by_name_reach_the_target(tmp_path, interface):
    """
    ``command_message: joint_state``: the commands as sensor_msgs/JointState on /joint_commands.

    Position, velocity and effort by joint name (the bridge reads them so); in joint impedance the
    gains are the drive's own, configured on the bridge as on the controller. The same reach as
    with Float64MultiArray: within 1 mm, within the limits.
    """
    wire = ('-p', 'command_message:=joint_state', '-p', 'command_topic:=/joint_commands')
    hand, states, robot, (log, bridge_log) = _reach(
        tmp_path, interface, both_args=wire,
        bridge_args=GAINS if interface == 'joint_impedance' else ())
    error = np.linalg.norm(hand - TARGET)
    lo, hi = robot.get_joint_position_limits()
    q = np.array([s[1] for s in states])
    print(f'{interface} as JointState: {error * 1e3:.3f} mm from the target')
    assert 'commands on /joint_commands' in bridge_log
    assert error < 1e-3
    assert (q >= lo).all() and (q <= hi).all()
    assert 'safe command' not in log and 'rejected' not in bridge_log, bridge_log[-2000:]


@pytest.mark.parametrize('interface', ['position', 'velocity'])
def test_the_kinematic_controller_drives_servos_without_a_dynamics_model(tmp_path, interface):
    """
    ``kinematic: true`` on a URDF without any <inertial>: the servos still reach the target.

    The controller knows nothing of the arm's dynamics (its URDF stripped of every inertia, the
    torque limit left out as it needs them); the bridge simulates the real arm. Within 1 mm and
    the joint limits, as with the full model.
    """
    import re

    with open(orca.default_urdf_path()) as fh:
        text = re.sub(r'<inertial>.*?</inertial>', '', fh.read(), flags=re.S)
    bare = tmp_path / 'lwr_without_inertias.urdf'
    bare.write_text(text)
    hand, states, robot, (log, bridge_log) = _reach(
        tmp_path, interface, controller_args=(
            '-p', 'kinematic:=true', '-p', f'urdf_path:={bare}',
            '-p', 'constraints.names:=[position_limit, velocity_limit]'))
    error = np.linalg.norm(hand - TARGET)
    lo, hi = robot.get_joint_position_limits()
    q = np.array([s[1] for s in states])
    print(f'kinematic, {interface}: {error * 1e3:.3f} mm from the target')
    assert error < 1e-3 and (q >= lo).all() and (q <= hi).all()
    assert 'safe command' not in log, log[-2000:]


def test_a_joint_state_command_is_read_by_name():
    """The JointState wire: fields by name in any order, the gains left to the drive."""
    from orca_ros.ros.command_wire import command_wire

    fields = ('position', 'velocity', 'effort', 'stiffness', 'damping')
    sender = command_wire('joint_state', fields, ['a', 'b'], lockstep=True)
    msg = sender.message()
    sender.write(msg, np.arange(10.0).reshape(5, 2), None)  # lockstep: no clock read
    sender.set_answered(msg, 1_500_000_001)
    assert list(msg.name) == ['a', 'b'] and list(msg.effort) == [4.0, 5.0]
    assert sender.answered(msg) == 1_500_000_001
    reader = command_wire('joint_state', fields, ['b', 'a'], lockstep=False)
    values = reader.read(msg)
    assert values[:3].tolist() == [[1.0, 0.0], [3.0, 2.0], [5.0, 4.0]]
    assert np.isnan(values[3:]).all()  # not carried
    msg.name = ['a', 'c']
    with pytest.raises(ValueError, match=r"no command for joints \['b'\]"):
        reader.read(msg)
    msg.name, msg.velocity = ['a', 'b'], [1.0]
    with pytest.raises(ValueError, match='1 velocity values for 2 names'):
        reader.read(msg)
    with pytest.raises(ValueError, match="command_message 'xml' is not one of"):
        command_wire('xml', fields, ['a'], lockstep=False)


@pytest.mark.parametrize('case', ['unknown', 'no_gains', 'negative_gain', 'gain_sizes',
                                  'bridge_unknown', 'message', 'bridge_message', 'bridge_gains',
                                  'kinematic_effort', 'kinematic_torque_limit'])
def test_a_bad_interface_or_gain_is_one_line_and_exit_1(tmp_path, case):
    """Refused at start with the cause named: no traceback, exit code 1."""
    procs = Procs(free_domain_id(), str(tmp_path))
    args, said = {
        'unknown': (('command_interface:=torque',), "'torque' is not one of"),
        'no_gains': (('command_interface:=joint_impedance', 'joint_stiffness:=[300.0]'),
                     'joint_impedance needs joint_stiffness and joint_damping'),
        'negative_gain': (('command_interface:=joint_impedance', 'joint_stiffness:=[-1.0]',
                           'joint_damping:=[1.0]'), 'joint_stiffness must be finite and >= 0'),
        'gain_sizes': (('command_interface:=joint_impedance', 'joint_stiffness:=[1.0, 2.0]',
                        'joint_damping:=[1.0]'), 'joint_stiffness: 2 values for 7 joints'),
        'bridge_unknown': (('command_interface:=mit',),
                           "command_interface 'mit' is not one of"),
        'message': (('command_message:=xml',), "'xml' is not one of"),
        'bridge_message': (('command_message:=xml',), "command_message 'xml' is not one of"),
        'bridge_gains': (('command_interface:=joint_impedance', 'command_message:=joint_state'),
                         'the bridge needs joint_stiffness and joint_damping'),
        'kinematic_effort': (('kinematic:=true', 'constraints.names:=[position_limit]'),
                             'kinematic: no torques to send as effort'),
        'kinematic_torque_limit': (('kinematic:=true', 'command_interface:=position'),
                                   "constraint 'torque_limit' (joint_torque_limit) needs the "
                                   'dynamics'),
    }[case]
    ros_args = [a for arg in args for a in ('-p', arg)]
    if case.startswith('bridge'):
        p, name = procs.start_arm_bridge('lockstep', *ros_args), 'bridge'
    else:
        p, name = procs.start_arm_controller('lockstep', *ros_args), 'controller'
    try:
        procs.assert_refused(p, name, said)
    finally:
        procs.stop()


@pytest.mark.parametrize('interface', ['position', 'velocity', 'joint_impedance'])
def test_disabled_the_drives_stop_and_hold_then_resume(tmp_path, interface):
    """
    Disabled mid-motion, the interface's hold stops the arm and keeps it; enabled, it resumes.

    Position: the reference stopped where it was; velocity: zero; joint impedance: the stopped
    reference with the gains and the effort hold. Lockstep, disabled at 0.8 s while the arm moves
    towards its target (the bridge's stop_time, then ~/unpause).
    Enabled again, the controller resumes from where the arm is (its targets reset there): no
    jump, then a new target 5 cm away reached.
    """
    from std_srvs.srv import SetBool, Trigger

    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'command_interface:={interface}')
    procs.start_arm(
        'lockstep',
        controller_args=('-p', f'tasks.ee.target_position:={TARGET}',
                         '-p', f'tasks.ee.target_rpy:={RPY}', *both,
                         *(GAINS if interface == 'joint_impedance' else ())),
        bridge_args=('-p', 'stop_time:=0.8', *both),
    )
    probe = Probe(domain)
    enable = '/orca_controller/enable'
    try:
        # the bridge stops at 0.8 s (stop_time), the arm half-way and moving; told, it resumes
        probe.wait_for(lambda: probe.sim_time() >= 0.8 - 1e-9, 120, 'the stop at 0.8 s')
        t_off = probe.sim_time()
        assert probe.call(SetBool, enable, SetBool.Request(data=False)).success
        assert probe.call(Trigger, '/pybullet_bridge/unpause', Trigger.Request()).success
        probe.wait_for(lambda: 'disabled' in probe.diagnostics.get('_message', ''), 60,
                       'diagnostics reporting the hold')
        probe.wait_sim(1.0, 120)
        _, q_held, v_held = probe.last_state()
        probe.wait_sim(0.5, 120)
        _, q_end, v_end = probe.last_state()
        drift = np.abs(q_end - q_held).max()
        with probe.lock:  # (the probe's best-effort copy may miss states on a busy machine)
            moving = max(np.abs(v).max() for t, _, v in probe.states if t_off - 0.2 <= t <= t_off)
        print(f'{interface}: moving at {moving:.3f} rad/s when disabled; 1 s on, at '
              f'{np.abs(v_held).max():.2e} rad/s, then {drift:.2e} rad in 0.5 s')
        assert moving > 0.05  # it was stopped in motion
        assert np.abs(v_end).max() < 1e-3 and drift < 1e-3
        hand = probe.ee_pose(q_end)[:3, 3]
        assert np.linalg.norm(hand - TARGET) > 0.02  # held short of the target
        assert probe.call(SetBool, enable, SetBool.Request(data=True)).success
        probe.wait_for(lambda: probe.diagnostics.get('_message') == 'controlling', 60,
                       'diagnostics back to controlling')
        probe.wait_sim(0.5, 120)
        resumed = np.abs(probe.last_state()[1] - q_end).max()
        target = probe.send_ee_offset([0.0, 0.0, 0.05])[:3, 3]
        probe.wait_for(lambda: np.linalg.norm(probe.ee_pose()[:3, 3] - target) < 1e-3, 120,
                       'the new target reached')
        print(f'resumed: moved {resumed:.2e} rad in 0.5 s, then reached a target 5 cm away')
        assert resumed < 1e-3
        assert 'recovered from: controller disabled' in procs.log('controller')
    finally:
        probe.close()
        procs.stop()


TICK = 0.004  # the free-running bridge's tick and the controller's period [s]


@pytest.mark.parametrize('interface', ['position', 'velocity', 'position_velocity',
                                       'joint_impedance'])
def test_a_cut_state_line_and_the_shutdown_stop_the_drives(tmp_path, interface):
    """
    Stale states and the shutdown: the interface's hold reaches the drives, and they stop the arm.

    Free running, the controller on its timer; it hears the simulator's joint states through the
    probe, which stops relaying them while the arm moves (a cut sensor line: the simulator and
    its drives go on). Past ``state_timeout`` the controller sends its hold, named in the log;
    the simulated arm stops and stays. The states back, it recovers and reaches its target. Then
    SIGTERM while it moves to another: the hold delivered on the way out, the arm stops again.
    Stopped: at rest (< 1e-3 rad/s) within 1 s of simulated time (3 s in joint impedance, see
    below), then still (< 1e-3 rad in 0.5 s). Time is counted in the bridge's states (one per
    tick of 4 steps of 1 ms), never on the wall clock. Both at 250 Hz: a free-running simulation
    that falls behind the wall clock (a loaded machine) runs its drives slower than the
    controller integrates their references.
    """
    import signal

    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'command_interface:={interface}')
    relayed = '/probe/joint_states'
    procs.start_arm(
        'free_running',
        controller_args=('-p', f'tasks.ee.target_position:={TARGET}',
                         '-p', f'tasks.ee.target_rpy:={RPY}', '-r', f'joint_states:={relayed}',
                         *both, *(GAINS if interface == 'joint_impedance' else ()),
                         '-p', f'update_rate:={1 / TICK}'),
        bridge_args=(*both, '-p', f'rate:={1 / TICK}'),
    )
    probe = Probe(domain, relay_states_to=relayed)

    def count():
        with probe.lock:
            return len(probe.states)

    def moving():
        return np.abs(probe.last_state()[2]).max() > 0.05

    # the servos stop the arm critically damped at 20 Hz; the joint impedance's gains, each
    # joint's own at 10 Hz, leave the coupled arm a mode at 2.2 Hz damped at 0.22 (a decay time
    # of 0.32 s: 5% left after 1 s, 1e-4 after 3 s)
    settle = int(round((3.0 if interface == 'joint_impedance' else 1.0) / TICK))

    def stops(what):
        """Wait for the arm to settle, then 0.5 s: the speed and the drift over that 0.5 s."""
        n, end = count(), settle + int(round(0.5 / TICK))
        probe.wait_for(lambda: count() > n + end, 120, f'the simulation after {what}')
        with probe.lock:
            after = probe.states[n:n + end]
        speed = max(np.abs(s[2]).max() for s in after[settle:])
        drift = max(np.abs(s[1] - after[settle][1]).max() for s in after[settle:])
        print(f'{interface}, {what}: {speed:.1e} rad/s after {settle * TICK:g} s, then '
              f'{drift:.1e} rad in 0.5 s')
        assert speed < 1e-3 and drift < 1e-3, (what, speed, drift)
        return after[-1][1]

    try:
        probe.wait_for(lambda: count() > 50 and moving(), 120, 'the arm moving to its target')
        probe.relay_states = False  # the controller's state line cut
        q_cut = probe.last_state()[1]
        probe.wait_for(lambda: 'safe command: joint_states stale' in procs.log('controller'), 60,
                       'the stale hold')
        q_held = stops('the state line cut')
        assert np.linalg.norm(probe.ee_pose(q_held)[:3, 3] - TARGET) > 0.02  # short of it
        # the arm stops within the braking distance of the fault (50 ms of state_timeout at the
        # speed it had, then the servo's stop): well within 0.1 rad
        assert np.abs(q_held - q_cut).max() < 0.1
        probe.relay_states = True
        probe.wait_for(lambda: 'recovered from: joint_states stale' in procs.log('controller'),
                       60, 'the recovery')
        probe.wait_for(lambda: np.linalg.norm(probe.ee_pose()[:3, 3] - TARGET) < 1e-3, 120,
                       'the target reached after the recovery')
        target = probe.send_ee_offset([0.0, 0.1, 0.0])[:3, 3]
        probe.wait_for(moving, 60, 'the arm moving to the new target')
        ctrl = procs.procs[1][0]
        ctrl.send_signal(signal.SIGTERM)
        assert ctrl.wait(timeout=30) == 0
        assert 'shutdown: hold command sent' in procs.log('controller')
        q_end = stops('the shutdown')
        assert np.linalg.norm(probe.ee_pose(q_end)[:3, 3] - target) > 0.02
        with probe.lock:
            last = probe.commands[-1].reshape(-1, 7)
        if interface != 'position':  # the hold's velocities: zero
            assert not last[1 if interface != 'velocity' else 0].any(), last
        assert 'watchdog' not in procs.log('bridge') or 'hold where' in procs.log('bridge')
    finally:
        probe.close()
        procs.stop()


def test_the_simulated_servos_stay_stable_at_every_posture(tmp_path):
    """
    The bridge's position servos, tuned to the posture of each step, are stable everywhere.

    The lwr stretched upright from its start posture by position commands along a smooth path
    (2 s, then held 0.5 s): its first joint's inertia with the others free drops 11x on the way.
    With the gains of the start posture the joint chattered at its effort limit there
    (K_d dt / m = 2.8 > 2: 10 rad/s each way, every step); tuned at each step it follows the path
    and comes to rest. The path's fastest joint moves at 1.9 rad/s: no state may be faster than
    that plus the servo's lag (at 20 Hz behind a path this smooth: a tenth of it).
    """
    from test_ros_nodes import _command_writer, _step
    from orca_ros.ros.testing.launch_free import ARM_Q0

    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm_bridge('lockstep', '-p', 'command_interface:=position',
                           '-p', 'control_period:=0.01')
    probe = Probe(domain)
    pub = _command_writer(probe)
    q0, q1 = np.array(ARM_Q0, dtype=float), np.zeros(7)
    duration, period = 2.0, 0.01
    try:
        probe.wait_for(lambda: probe.sim_time() >= 0.0, 60, "the simulator's first state")
        for k in range(1, int(round((duration + 0.5) / period)) + 1):
            x = min(k * period / duration, 1.0)
            s = 10 * x**3 - 15 * x**4 + 6 * x**5  # quintic: at rest at both ends
            _step(probe, pub, q0 + s * (q1 - q0))
        with probe.lock:
            states = list(probe.states)
        log = procs.log('bridge')
    finally:
        probe.close()
        procs.stop()
    fastest_path = 1.875 * np.abs(q1 - q0).max() / duration  # the quintic's peak speed
    speed = max(np.abs(v).max() for _, _, v in states)
    _, q_end, v_end = states[-1]
    print(f'fastest joint {speed:.2f} rad/s (the path: {fastest_path:.2f}); at the end '
          f'{np.abs(q_end - q1).max():.1e} rad from the upright pose, {np.abs(v_end).max():.1e} '
          'rad/s')
    assert speed < 1.1 * fastest_path
    assert np.abs(v_end).max() < 1e-3 and np.abs(q_end - q1).max() < 1e-3
    assert 'rejected' not in log


def test_the_joint_impedance_gains_change_live(tmp_path):
    """
    ``joint_stiffness`` and ``joint_damping`` are live: checked, then in the next commands.

    A request is all or nothing: a negative gain or a wrong count is refused with its cause and
    the gains in the commands stay as they were. The arm keeps to its target throughout.
    """
    from test_ros_live_parameters import set_params

    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', 'command_interface:=joint_impedance')
    procs.start_arm('lockstep', controller_args=(*both, *GAINS), bridge_args=both)
    probe = Probe(domain)
    stiffness = np.array(json.loads(GAINS[1].split(':=')[1]))

    def sent(row):
        with probe.lock:
            return probe.commands[-1].reshape(5, 7)[row].copy() if probe.commands else None

    try:
        probe.wait_for(lambda: probe.sim_time() > 0.3 and sent(3) is not None, 120,
                       'the controller driving the arm')
        assert np.array_equal(sent(3), stiffness)
        doubled = (2 * stiffness).tolist()
        res = set_params(probe, joint_stiffness=doubled, joint_damping=[3.0])
        assert all(r.successful for r in res), [r.reason for r in res]
        probe.wait_for(lambda: np.array_equal(sent(3), doubled) and (sent(4) == 3.0).all(), 60,
                       'the commands carrying the new gains')
        for bad, cause in (([-1.0], 'outside [0, 1e+06]'), ([1.0, 2.0], '2 values for 7')):
            res = set_params(probe, joint_stiffness=bad)
            assert not res[0].successful and cause in res[0].reason, res[0].reason
        probe.wait_sim(0.2)
        assert np.array_equal(sent(3), doubled)
        hand = probe.ee_pose()[:3, 3]
        assert np.linalg.norm(hand - probe.ee_pose(np.array(ARM_Q0))[:3, 3]) < 1e-3
    finally:
        probe.close()
        procs.stop()
