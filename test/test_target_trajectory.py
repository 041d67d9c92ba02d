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
