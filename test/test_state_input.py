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
RobotModel state input.

The Pinocchio-convention setter agrees with the odometry-style one; bad input rejected.
"""

import numpy as np
import orca_ros as orca
import pinocchio as pin
import pytest


def _quadruped():
    r = orca.RobotModel()
    r.load_model_from_file(orca.share_path('urdf', 'quadruped.urdf'), floating_base=True)
    return r


def test_configuration_matches_world_pose_and_twist():
    rng = np.random.default_rng(3)
    a, b = _quadruped(), _quadruped()
    model = a.model
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v = rng.normal(size=model.nv)
    a.set_configuration(q, v)
    T = pin.XYZQUATToSE3(q[:7]).homogeneous
    R = T[:3, :3]
    b.set_robot_state(T, q[7:], np.concatenate((R @ v[:3], R @ v[3:6])), v[6:], a.get_gravity())
    np.testing.assert_allclose(a.get_mass_matrix(), b.get_mass_matrix(), atol=1e-12)
    np.testing.assert_allclose(
        a.get_generalized_gravity_and_coriolis_torques(),
        b.get_generalized_gravity_and_coriolis_torques(),
        atol=1e-10,
    )
    for f in ('FL_foot', 'HR_foot'):
        np.testing.assert_allclose(a.get_frame_pose(f), b.get_frame_pose(f), atol=1e-12)
        np.testing.assert_allclose(a.get_frame_velocity(f), b.get_frame_velocity(f), atol=1e-10)
    # the odometry-style getters are derived from q, v
    np.testing.assert_allclose(a.get_world_to_base_transform(), T, atol=1e-12)
    np.testing.assert_allclose(a.get_base_velocity(), b.get_base_velocity(), atol=1e-12)
    np.testing.assert_allclose(a.get_joint_positions(), q[7:])
    np.testing.assert_allclose(a.get_joint_velocities(), v[6:])


def test_configuration_rejects_bad_input_and_keeps_the_previous_state():
    r = _quadruped()
    q = pin.neutral(r.model)
    v = np.zeros(r.model.nv)
    r.set_configuration(q, v)
    M = r.get_mass_matrix().copy()
    bad_q = q.copy()
    bad_q[3:7] = [0.0, 0.0, 0.0, 2.0]
    with pytest.raises(ValueError, match='quaternion'):
        r.set_configuration(bad_q, v)
    nan_v = v.copy()
    nan_v[4] = np.nan
    with pytest.raises(ValueError, match='NaN'):
        r.set_configuration(q, nan_v)
    with pytest.raises(ValueError, match='shape'):
        r.set_configuration(q[:-1], v)
    huge = v.copy()
    huge[:] = (
        # finite but absurd values overflow the quick sum test: the exact test lets them through
        1e308
    )
    r.set_configuration(q, huge)
    r.set_configuration(q, v)
    np.testing.assert_allclose(r.get_mass_matrix(), M)
