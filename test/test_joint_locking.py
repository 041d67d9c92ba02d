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
Joints locked in the model at their measured positions (a gripper's fingers, a robot's head).

The reduced model must be the full model with those joints frozen: same mass matrix, bias forces
and frame kinematics on the remaining joints, on an arm (Panda of ``pybullet_data``) and a humanoid
(Talos of ``example-robot-data``, floating base).
"""

import os

import numpy as np
import orca_ros as orca
from orca_ros.configuration import build_from_config, ConfigError
from orca_ros.ros.joint_state_input import JointStateInput, StateRejected
import pybullet_data
import pytest

PANDA = os.path.join(pybullet_data.getDataPath(), 'franka_panda', 'panda.urdf')
FINGERS = ['panda_finger_joint1', 'panda_finger_joint2']


def _compare(locked, full, keep, frame, atol=1e-9):
    """Locked-model quantities against the full model's rows/columns of the kept joints."""
    nb = 6 if full.is_floating_base() else 0
    cols = np.r_[np.arange(nb), nb + np.asarray(keep)]
    np.testing.assert_allclose(
        locked.get_mass_matrix(), full.get_mass_matrix()[np.ix_(cols, cols)], atol=atol
    )
    np.testing.assert_allclose(
        locked.get_generalized_gravity_and_coriolis_torques(),
        full.get_generalized_gravity_and_coriolis_torques()[cols],
        atol=atol,
    )
    np.testing.assert_allclose(locked.get_frame_pose(frame), full.get_frame_pose(frame), atol=atol)
    np.testing.assert_allclose(
        locked.get_frame_jacobian(frame), full.get_frame_jacobian(frame)[:, cols], atol=atol
    )
    np.testing.assert_allclose(
        locked.get_frame_bias_acceleration(frame),
        full.get_frame_bias_acceleration(frame),
        atol=atol,
    )


def test_panda_with_locked_fingers_is_the_full_model_frozen(rng):
    full, locked = orca.RobotModel(), orca.RobotModel()
    full.load_model_from_file(PANDA)
    locked.load_model_from_file(PANDA)
    locked.lock_joints(FINGERS)
    assert locked.get_joint_names() == [f'panda_joint{i}' for i in range(1, 8)]
    assert locked.get_nr_of_degrees_of_freedom() == 7
    assert locked.get_locked_joint_names() == FINGERS
    lo, hi = full.get_joint_position_limits()
    fid = locked.get_frame_id('panda_leftfinger')
    for k in range(5):
        q = rng.uniform(lo[:7], hi[:7])
        v = rng.uniform(-1, 1, 7)
        fingers = rng.uniform(0.0, 0.04, 2)
        locked.set_robot_state(q, v)
        locked.set_locked_joint_positions(fingers)  # re-welds, keeps the state just set
        np.testing.assert_array_equal(locked.get_joint_positions(), q)
        full.set_robot_state(np.r_[q, fingers], np.r_[v, 0.0, 0.0])
        _compare(locked, full, np.arange(7), 'panda_leftfinger')
        assert locked.get_frame_id('panda_leftfinger') == fid  # structure kept across welds


def test_relocking_only_beyond_the_tolerance():
    robot = orca.RobotModel()
    robot.load_model_from_file(PANDA)
    robot.lock_joints(FINGERS, positions=[0.02, 0.02], tolerance=1e-4)
    model = robot.model
    assert not robot.set_locked_joint_positions([0.02 + 5e-5, 0.02])
    assert robot.model is model
    assert robot.set_locked_joint_positions([0.02, 0.025])
    assert robot.model is not model
    np.testing.assert_array_equal(robot.get_locked_joint_positions(), [0.02, 0.025])
    with pytest.raises(ValueError, match='2 locked joints'):
        robot.set_locked_joint_positions([0.02])
    with pytest.raises(ValueError, match='NaN'):
        robot.set_locked_joint_positions([np.nan, 0.02])
    with pytest.raises(ValueError, match="cannot lock joint 'gripper'"):
        robot.lock_joints(['gripper'])
    robot.lock_joints([])  # back to the full model
    assert robot.get_nr_of_degrees_of_freedom() == 9


def test_talos_lower_body_with_locked_arms_and_head(example_robot_urdf, rng):
    urdf = example_robot_urdf('talos_data/robots/talos_reduced.urdf')
    full, locked = orca.RobotModel(), orca.RobotModel()
    full.load_model_from_file(urdf, floating_base=True)
    locked.load_model_from_file(urdf, floating_base=True)
    names = full.get_joint_names()
    frozen = [n for n in names if n.startswith(('arm_', 'head_', 'gripper_'))]
    keep = [k for k, n in enumerate(names) if n not in frozen]
    locked.lock_joints(frozen)
    assert locked.get_joint_names() == [names[k] for k in keep]
    lo, hi = full.get_joint_position_limits()
    q = np.clip(rng.uniform(-0.5, 0.5, len(names)), lo, hi)
    v = rng.uniform(-0.5, 0.5, len(names))
    T = np.eye(4)
    T[:3, 3] = [0.1, -0.2, 1.0]
    twist = rng.uniform(-0.3, 0.3, 6)
    g = np.array([0.0, 0.0, -9.81])
    frozen_q = np.array([q[names.index(n)] for n in frozen])
    locked.set_locked_joint_positions(frozen_q)
    locked.set_robot_state(T, q[keep], twist, v[keep], g)
    v_full = v.copy()
    v_full[[names.index(n) for n in frozen]] = 0.0  # locked joints do not move
    full.set_robot_state(T, q, twist, v_full, g)
    _compare(locked, full, keep, 'left_sole_link', atol=1e-8)
    np.testing.assert_allclose(locked.get_center_of_mass(), full.get_center_of_mass(), atol=1e-9)


def test_configuration_with_a_subset_of_joints(lwr_urdf):
    arm = [f'panda_joint{i}' for i in range(1, 8)]
    setup = build_from_config({'urdf_path': PANDA, 'joints': list(reversed(arm))})
    assert setup.robot.get_locked_joint_names() == FINGERS
    assert setup.joints == list(reversed(arm))
    np.testing.assert_array_equal(setup.model_index, np.arange(6, -1, -1))
    with pytest.raises(ConfigError, match=r"unknown: \['gripper'\]"):
        build_from_config({'urdf_path': PANDA, 'joints': arm + ['gripper']})
    with pytest.raises(ConfigError, match='duplicates'):
        build_from_config({'urdf_path': PANDA, 'joints': arm + arm[:1]})


def test_joint_states_must_carry_the_locked_joints():
    arm = [f'panda_joint{i}' for i in range(1, 8)]
    setup = build_from_config({'urdf_path': PANDA, 'joints': arm})
    reader = JointStateInput(setup.robot, setup.joints, setup.model_index)
    q, v = np.zeros(7), np.zeros(7)
    names = setup.joints + FINGERS
    pos = [0.0, -0.3, 0.0, -2.0, 0.0, 2.0, 0.8, 0.01, 0.03]
    reader.read(names, pos, [0.0] * 9, q, v)
    np.testing.assert_array_equal(reader.locked_positions, [0.01, 0.03])
    np.testing.assert_array_equal(q, pos[:7])
    with pytest.raises(StateRejected, match=r"missing joints \['panda_finger_joint2'\]"):
        reader.read(names[:8], pos[:8], [0.0] * 8, q, v)
    with pytest.raises(StateRejected, match='panda_finger_joint1 position 0.5'):
        reader.read(names, pos[:7] + [0.5, 0.03], [0.0] * 9, q, v)
    with pytest.raises(StateRejected, match=r"NaN or infinite position/velocity of \['panda_fin"):
        reader.read(names, pos[:7] + [np.nan, 0.03], [0.0] * 9, q, v)
