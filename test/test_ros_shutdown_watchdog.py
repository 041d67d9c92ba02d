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
Signals.

A killed controller, and diagnostics that tell the truth (real processes on a private domain).

Time is counted in simulated steps (lockstep, or the free-running bridge's one step per tick),
never in wall-clock limits, so these hold on a busy machine.
"""

import signal
import time

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest


_ROBOT = []
# the node computes the hold as the probe's model does, from the same state: measured 0 Nm (bit
# for bit); 1e-9 Nm leaves room for round-off in another summation order
HOLD_TOL = 1e-9


def gravity(q):
    if not _ROBOT:
        _ROBOT.append(orca.RobotModel())
        _ROBOT[0].load_model_from_file(orca.default_urdf_path())
    _ROBOT[0].set_robot_state(np.asarray(q), np.zeros(7))
    return _ROBOT[0].get_joint_gravity_torques().copy()


def tracking(probe):
    """Largest joint torque beyond gravity in the last command (at the last state)."""
    if not probe.commands or not probe.states:
        return 0.0
    return np.abs(probe.commands[-1] - gravity(probe.states[-1][1])).max()


def start(tmp_path, mode, *controller_args, bridge_args=(), simulator='pybullet'):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm(mode, controller_args=controller_args, bridge_args=bridge_args,
                    simulator=simulator)
    return procs, Probe(domain)


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM])
def test_signal_sends_the_hold_and_exits_cleanly(tmp_path, sig):
    procs, probe = start(tmp_path, 'lockstep')
    try:
        probe.wait_for(lambda: probe.sim_time() > 0.8, 60, 'the controller driving the bridge')
        target = probe.ee_pose()
        target[:3, 3] += [0.1, -0.1, 0.05]
        # moving, the last tracking command is far from the hold: the signal comes once it is
        probe.send_target('ee', target, until=lambda: tracking(probe) > 1.8)
        ctrl = procs.procs[1][0]
        ctrl.send_signal(sig)
        assert ctrl.wait(timeout=30) == 0
        log = procs.log('controller')
        assert 'Traceback' not in log and 'FATAL' not in log, log[-3000:]
        assert 'shutdown: hold command sent' in log

        # the hold is gravity at the last state the controller saw: one of the last instants
        # published (the bridge took one more step on the hold itself, and re-announces its
        # last state while no command comes)
        def gap():
            with probe.lock:
                last = probe.commands[-1] if probe.commands else None
                instants = {s[0]: s[1] for s in probe.states[-50:]}
            if last is None:
                return np.inf
            return min(np.abs(last - gravity(instants[t])).max() for t in sorted(instants)[-3:])

        # the hold was acknowledged by every reliable reader, the probe's too: it is on its way
        # to the probe's callback, which it may not have reached yet
        probe.wait_for(lambda: gap() < HOLD_TOL, 30, 'the hold (gravity at the last state)')
        with probe.lock:
            before, hold = probe.commands[-2], probe.commands[-1]
        print(
            f'the last command is {gap():.2g} Nm from the hold, '
            f'{np.abs(hold - before).max():.2f} Nm from the one before'
        )
        assert np.abs(hold - before).max() > 1.0, (
            'the arm was not moving: this test would not tell the hold from the last command'
        )
    finally:
        probe.close()
        procs.stop()


@pytest.mark.parametrize('simulator', ['pybullet', 'mujoco'])
def test_killed_controller_bridge_holds(tmp_path, simulator):
    procs, probe = start(
        tmp_path, 'free_running',
        bridge_args=('-p', 'rate:=1000.0', '-p', 'command_timeout:=0.02'), simulator=simulator,
    )
    try:
        probe.wait_for(lambda: len(probe.commands) > 1500, 120, 'the controller running')
        target = probe.ee_pose()
        target[:3, 3] += [0.0, 0.3, -0.1]
        probe.send_target('ee', target, until=probe.moved_towards(target))

        def ee_speed():
            # from the last state's joint velocities (no timing: messages may be dropped under
            # load)
            s = probe.last_state()
            probe.robot.set_robot_state(s[1], s[2])
            return np.linalg.norm(probe.robot.get_frame_velocity('link_7')[:3])

        # killed at cruise speed along the trajectory to the target (0.25 m/s by default)
        probe.wait_for(lambda: ee_speed() > 0.2, 60, 'the arm moving towards the target')
        kill_time = time.time()
        procs.procs[1][0].send_signal(signal.SIGKILL)
        # free running, states are stamped with the wall clock when published: the pose at the kill
        # is the last one published before it, whenever the probe received it
        probe.wait_for(
            lambda: probe.last_state()[0] > kill_time + 0.1, 60, 'states after the kill'
        )
        with probe.lock:
            before = [s for s in probe.states if s[0] <= kill_time]
        at_kill = probe.ee_pose(before[-1][1])
        probe.robot.set_robot_state(before[-1][1], before[-1][2])
        v_kill = np.linalg.norm(probe.robot.get_frame_velocity('link_7')[:3])

        def after():
            with probe.lock:
                return [s for s in probe.states if s[0] > kill_time]

        # 2 s of simulated time: the free-running bridge advances one 1 ms step per published
        # state (states the probe missed only lengthen the window)
        probe.wait_for(lambda: len(after()) >= 2000, 120, '2 s of simulation after the kill')
        window = after()[:2000]
        ee = np.array([probe.ee_pose(s[1])[:3, 3] for s in window])
        moved = np.linalg.norm(ee - at_kill[:3, 3], axis=1).max()
        print(
            f'killed at {v_kill:.3f} m/s: the end effector moved {moved * 1e3:.1f} mm, '
            f'{np.abs(window[-1][2]).max():.2g} rad/s 2 s later'
        )
        # at most v_kill for the 20 ms without a command (command_timeout) and the 50 ms fade into
        # the hold (hold_ramp), then braking at hold_damping 20 /s (1/20 s more at v_kill): 0.12 s
        # at v_kill, with half again for the arm's acceleration within the fade (measured 0.11 to
        # 0.14 s at v_kill). From the speed at the kill, not the 0.25 m/s cruise: the free-running
        # simulation lags the wall clock on a loaded machine and the controller's wall-clock
        # target ramp then drives the arm faster (killed at 1.0 m/s beside two burners)
        bound = 1.5 * v_kill * (0.02 + 0.05 + 1.0 / 20.0)
        assert moved < bound, (
            f'end effector moved {moved * 1e3:.0f} mm in the 2 s after the controller died '
            f'(at {v_kill:.3f} m/s: {bound * 1e3:.0f} mm at most)'
        )
        # damped at 20 /s for ~2 s (e^-40 of the motion): round-off, measured 3e-15 rad/s
        rest = np.abs(window[-1][2]).max()
        assert rest < 1e-12, f'not at rest 2 s after the kill ({rest:.2g} rad/s)'
        log = procs.log('bridge')
        assert 'holding (gravity + damping)' in log and 'no effort command for' in log
        assert 'Traceback' not in log
    finally:
        probe.close()
        procs.stop()


def _level_after_fault(probe, reports=2, timeout=120.0):
    """Level and message of the ``reports``-th diagnostics report received from now on."""
    seen = [probe.diagnostics]  # the probe replaces this dict on every report

    def grab():
        d = probe.diagnostics
        if d is not seen[-1]:
            seen.append(d)
        return len(seen) > reports

    probe.wait_for(grab, timeout, 'diagnostics reports')
    return seen[reports].get('_level'), seen[reports].get('_message')


def test_diagnostics_error_on_failing_qp(tmp_path):
    # 0.1 Nm torque limits cannot hold the arm against gravity: the QP is infeasible from the
    # start. Not at every state: the arm falls, and where a free fall fits the joints' viable
    # bounds a cycle solves (the log says 'recovered'); a report just after such a cycle names
    # the failures and the last one's cause
    procs, probe = start(tmp_path, 'lockstep', '-p', 'constraints.torque_limit.max:=0.1')
    try:
        probe.wait_for(lambda: len(probe.commands) > 50, 60, 'commands')
        level, message = _level_after_fault(probe)
        assert level == 2 and 'no QP solution' in message, message
        # the node says which constraints conflict (diagnose(), once per failing spell)
        procs.wait_log('controller', 'QP failure diagnosis: infeasible: conflicting constraints')
        line = [ln for ln in procs.log('controller').splitlines() if 'diagnosis' in ln][0]
        assert 'torque_limit' in line, line
        probe.wait_for(lambda: 'torque_limit' in probe.diagnostics.get('qp_conflict', ''), 30,
                       'the conflict in /diagnostics')
        cmds = np.array(probe.commands)
        assert np.isfinite(cmds).all() and (np.abs(cmds) <= 176.0).all()
    finally:
        probe.close()
        procs.stop()


def test_diagnostics_ok_then_error_on_stale_state_then_warn_on_overruns(tmp_path):
    # healthy must be reachable on a busy machine (two CPU burners: a 500 Hz loop overran for
    # good): 200 Hz, overruns counted above 5 periods; the overrun case below fails anywhere
    procs, probe = start(
        tmp_path,
        'free_running',
        '-p',
        'update_rate:=200.0',
        '-p',
        'overrun_factor:=5.0',
        '-p',
        'state_timeout:=0.1',
        bridge_args=(
            '-p',
            'rate:=200.0',
        ),
    )
    try:
        probe.wait_for(lambda: len(probe.commands) > 400, 120, 'the controller running')
        probe.wait_for(
            lambda: probe.diagnostics.get('_level') == 0, 60, 'an OK report while healthy'
        )
        procs.procs[0][0].send_signal(signal.SIGKILL)  # the bridge dies: no more joint states
        level, message = _level_after_fault(probe)
        assert level == 2 and 'stale' in message, message
        n = len(probe.commands)
        probe.wait_for(lambda: len(probe.commands) > n + 50, 30, 'safe commands')
        assert np.isfinite(np.array(probe.commands[n:])).all()
        assert procs.procs[1][0].poll() is None
    finally:
        probe.close()
        procs.stop()
    # a nominal rate no machine reaches in Python: every period overruns
    (tmp_path / 'fast').mkdir()
    procs, probe = start(
        tmp_path / 'fast',
        'free_running',
        '-p',
        'update_rate:=20000.0',
        bridge_args=(
            '-p',
            'rate:=500.0',
        ),
    )
    try:
        probe.wait_for(lambda: len(probe.commands) > 200, 120, 'the controller running')
        level, message = _level_after_fault(probe)
        assert level >= 1 and 'loop overruns' in message, message
    finally:
        probe.close()
        procs.stop()
