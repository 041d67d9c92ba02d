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
A 30 cm target step becomes a jerk-limited trajectory.

No torque step, a straight path at the set speed.
"""

import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe

STEP = np.array([0.0, 0.25, -0.15])  # 29 cm
TORQUE_STEP_BOUND = 2.0  # Nm per 1 ms cycle


def run_step(tmp_path, *args):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm('lockstep', controller_args=args)
    probe = Probe(domain)
    try:
        probe.wait_for(lambda: probe.sim_time() > 1.0, 60, 'the controller driving the bridge')
        start = probe.ee_pose()
        target = start.copy()
        target[:3, 3] += STEP
        n_state = len(probe.states)
        t0 = probe.sim_time()
        probe.send_target('ee', target, until=probe.moved_towards(target))
        probe.wait_sim(3.0)
        # from the simulator's applied torques, between consecutive steps only
        step = probe.max_torque_step(t0, probe.sim_time())
        states = probe.states[n_state:]
        path = np.array([probe.ee_pose(s[1])[:3, 3] for s in states])
        times = np.array([s[0] for s in states])
        assert 'Traceback' not in procs.log('controller')
        return start, target, step, path, times
    finally:
        probe.close()
        procs.stop()


def test_target_step_follows_a_jerk_limited_path(tmp_path):
    start, target, step, path, times = run_step(tmp_path)
    assert step < TORQUE_STEP_BOUND, f'torque step {step:.2f} Nm in one cycle'
    # straight line from start to target, at most the trajectory's 0.25 m/s, arriving when Ruckig
    # says
    d = (target[:3, 3] - start[:3, 3]) / np.linalg.norm(STEP)
    rel = path - start[:3, 3]
    off_line = np.linalg.norm(rel - np.outer(rel @ d, d), axis=1).max()
    assert off_line < 5e-3, f'path leaves the straight line by {off_line * 1e3:.1f} mm'
    # one sample per instant: a paused lockstep simulator announces its state again (same stamp)
    times, first = np.unique(times, return_index=True)
    path, rel = path[first], rel[first]
    speed = np.linalg.norm(np.diff(path, axis=0), axis=1) / np.diff(times)
    assert speed.max() < 0.25 * 1.1, f'peak speed {speed.max():.3f} m/s'
    from orca_ros.servo.target_trajectory import CartesianTrajectory

    profile = CartesianTrajectory([0.25, 1.0], [1.0, 3.0], [5.0, 15.0])
    duration = profile.start(0.0, start, np.zeros(6), np.zeros(6), target)

    def along(t):
        return profile.sample(t)[0][:3, 3] @ d - start[:3, 3] @ d

    # the profile starts when the controller took the target (the probe repeats it until it acts,
    # later on a busy machine): found where the end effector first moves 10 um along the line,
    # minus the time the profile itself takes to get there (its jerk-limited start)
    fine = np.arange(0.0, 0.2, 1e-4)
    tau = fine[np.argmax([along(t) > 1e-5 for t in fine])]
    t_start = times[np.argmax(rel @ d > 1e-5)] - tau
    progress = np.array([along(t - t_start) for t in times])
    lag = np.abs(rel @ d - progress).max()
    assert lag < 0.02, f'the end effector is {lag * 1e3:.1f} mm from the profile at worst'
    err = np.linalg.norm(path[-1] - target[:3, 3])
    assert err < 1e-3 and times[-1] - t_start > duration


def test_without_trajectory_the_step_hits_the_servo(tmp_path):
    """The same step with trajectories disabled: what the bound above protects against."""
    _, _, step, _, _ = run_step(tmp_path, '-p', 'tasks.ee.trajectory.enabled:=false')
    assert step > 5 * TORQUE_STEP_BOUND
