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
The reference's simulator examples, on PyBullet.

Each runs headless and checks its own outcome.
"""

import numpy as np
from orca_ros.examples import (
    sim_controller_in_the_loop,
    sim_gravity_compensation,
    sim_multiple_robots,
    sim_single_robot,
)


def test_single_robot_falls_without_command(lwr_urdf):
    res = sim_single_robot.run(lwr_urdf, duration=1.0)
    assert np.abs(res['q'] - res['q0']).max() > 0.1
    assert len(res['log']) == 10  # after-step callback ran every step (logged every 100th)


def test_gravity_compensation_holds_the_arm(lwr_urdf):
    held = sim_gravity_compensation.run(lwr_urdf, 1.0, compensate=True)
    fell = sim_gravity_compensation.run(lwr_urdf, 1.0, compensate=False)
    assert np.abs(held['q'] - held['q0']).max() < 1e-6
    assert np.abs(fell['q'] - fell['q0']).max() > 0.1
    assert np.abs(held['measured']).max() > 10.0  # the measured effort is the applied compensation


def test_multiple_robots_are_independent(lwr_urdf):
    res = sim_multiple_robots.run(lwr_urdf, 1.0)
    assert res['set_ok']
    assert res['left_moved'] < 1e-6 and res['right_moved'] > 0.05
    np.testing.assert_allclose(res['bases'][0], [0, -0.6, 0], atol=1e-9)
    np.testing.assert_allclose(res['bases'][1], [0, 0.6, 0], atol=1e-9)


def test_controller_in_the_loop_tracks_min_jerk_trajectory(lwr_urdf):
    res = sim_controller_in_the_loop.run(lwr_urdf, duration=4.0)
    assert res['legs'] >= 1
    assert res['max_error'] < 5e-3
