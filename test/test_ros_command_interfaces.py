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

import numpy as np
import orca_ros as orca
from orca_ros.ros.launch_free import free_domain_id, Procs
from orca_ros.ros.probe import Probe
import pytest

TARGET = [-0.45, -0.2, 0.45]
RPY = [3.14159, -0.84159, 3.14159]
GAINS = ('-p', 'joint_stiffness:=[300.0]', '-p', 'joint_damping:=[10.0]')


def _reach(tmp_path, interface: str, simulator: str = 'pybullet', duration: float = 3.0):
    """Run to ``duration`` s of simulated time; return the final hand position, states, logs."""
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'command_interface:={interface}')
    procs.start_arm(
        'lockstep',
        simulator=simulator,
        controller_args=('-p', f'tasks.ee.target_position:={TARGET}',
                         '-p', f'tasks.ee.target_rpy:={RPY}', *both,
                         *(GAINS if interface == 'joint_impedance' else ())),
        bridge_args=('-p', f'stop_time:={duration}', *both),
    )
    probe = Probe(domain)
    try:
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


@pytest.mark.parametrize('interface', ['position', 'velocity', 'position_velocity',
                                       'joint_impedance'])
def test_each_interface_reaches_the_target_within_the_joint_limits(tmp_path, interface):
    """
    Within 1 mm of the target after 3 s, as with efforts; positions and speeds within the limits.

    Measured on the simulated joints (the bridge's joint_states), every step.
    """
    hand, states, robot, (log, bridge_log) = _reach(tmp_path, interface)
    error = np.linalg.norm(hand - TARGET)
    lo, hi = robot.get_joint_position_limits()
    vmax = robot.get_joint_velocity_limits()
    q = np.array([s[1] for s in states])
    v = np.array([s[2] for s in states])
    speed = (np.abs(v) / vmax).max()
    print(f'{interface}: {error * 1e3:.3f} mm from the target; fastest joint at {speed:.2f} of '
          f'its limit; least room to a position limit {min((q - lo).min(), (hi - q).min()):.3f}')
    assert error < 1e-3
    assert (q >= lo).all() and (q <= hi).all()
    assert speed <= 1.0
    assert 'safe command' not in log, log[-2000:]
    assert 'rejected' not in bridge_log, bridge_log[-2000:]


@pytest.mark.parametrize('case', ['unknown', 'no_gains', 'negative_gain', 'gain_sizes',
                                  'bridge_unknown'])
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
        'bridge_unknown': (('command_interface:=mit',), "command_interface 'mit' is not one of"),
    }[case]
    ros_args = [a for arg in args for a in ('-p', arg)]
    if case.startswith('bridge'):
        p, name = procs.start_arm_bridge('lockstep', *ros_args), 'bridge'
    else:
        p, name = procs.start_arm_controller('lockstep', *ros_args), 'controller'
    try:
        assert p.wait(timeout=120) == 1
        log = procs.log(name)
        assert said in log, log
        assert 'Traceback' not in log, log
    finally:
        procs.stop()
