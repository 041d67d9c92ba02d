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
A driver that publishes positions only: the controller estimates the velocities and controls.

``JointState`` may legally carry empty velocity arrays. The bridge with
``publish_velocities: false`` stands for such a driver; the shipped lwr configuration, lockstep.
"""

import numpy as np
import orca_ros as orca
from orca_ros.robot.velocity_estimator import VelocityEstimator
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest

# 29 cm from the hand at the lockstep start (the posture), at its orientation: a configured target
# the controller moves to along its trajectory (1.5 s), a straight line clear of the arm
TARGET = [-0.45, -0.2, 0.45]
RPY = [3.14159, -0.84159, 3.14159]


def _run(tmp_path, velocities: bool, simulator: str):
    domain = free_domain_id()
    run = tmp_path / f'velocities_{velocities}'
    run.mkdir()
    procs = Procs(domain, str(run))
    procs.start_arm(
        'lockstep',
        simulator=simulator,
        controller_args=('-p', f'tasks.ee.target_position:={TARGET}',
                         '-p', f'tasks.ee.target_rpy:={RPY}'),
        bridge_args=('-p', 'stop_time:=3.0', '-p', f'publish_velocities:={velocities}'),
    )
    probe = Probe(domain)
    try:
        probe.wait_for(lambda: probe.sim_time() >= 3.0 - 1e-9, 120, 'the end of the run')
        _, q, _ = probe.last_state()
        log = procs.log('controller')
    finally:
        probe.close()
        procs.stop()
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(q, np.zeros(7))
    return robot.get_frame_pose('link_7')[:3, 3], log


@pytest.mark.parametrize('simulator', ['pybullet', 'mujoco'])
def test_positions_only_reach_the_target_as_with_velocities(tmp_path, simulator):
    """
    The end effector ends within 2 mm of where the run with velocities ends (and at the target).

    The controller says once that it estimates them. On either bridge (``publish_velocities``).
    """
    with_v, log_v = _run(tmp_path, True, simulator)
    without_v, log = _run(tmp_path, False, simulator)
    gap = np.linalg.norm(without_v - with_v)
    print(f'end effector: {with_v} with velocities, {without_v} without: {gap * 1e3:.3f} mm')
    assert gap < 2e-3
    assert np.linalg.norm(with_v - TARGET) < 1e-3
    assert log.count('joint_states carry no velocities') == 1, log
    assert 'carry no velocities' not in log_v


def test_the_estimate_follows_a_ramp_and_restarts_after_a_gap():
    est = VelocityEstimator(2, cutoff=100.0)
    t, v = 0.0, np.array([0.5, -2.0])
    out = est.update(np.zeros(2), t)
    np.testing.assert_array_equal(out, 0.0)  # nothing to differentiate yet
    for k in range(1, 101):  # 0.1 s at 1 kHz: ~10 time constants
        out = est.update(v * k * 1e-3, k * 1e-3)
    np.testing.assert_allclose(out, v, rtol=1e-4)
    before = out.copy()
    np.testing.assert_array_equal(est.update(np.ones(2), 0.1), before)  # the same instant
    np.testing.assert_array_equal(est.update(np.ones(2), 0.5), 0.0)  # after a 0.4 s gap
    est.update(np.full(2, 1.001), 0.501)
    assert np.abs(est.v).max() > 0.0
    np.testing.assert_array_equal(est.update(np.ones(2), 0.001), 0.0)  # the clock went back
    with pytest.raises(ValueError, match='cutoff'):
        VelocityEstimator(1, cutoff=0.0)
