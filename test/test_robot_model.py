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
"""RobotModel against Pinocchio's own algorithms and against finite differences."""

import numpy as np
import orca_ros as orca
import pinocchio as pin
import pytest

ROBOTS = [
    ('lwr', 'link_7', 'base_link', 'link_3'),
    ('iiwa', 'lbr_iiwa_link_7', 'lbr_iiwa_link_0', 'lbr_iiwa_link_3'),
]


def _load(request, which):
    urdf = request.getfixturevalue('lwr_urdf' if which == 'lwr' else 'iiwa_urdf')
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    return robot, urdf


def _random_state(robot, rng):
    lo, hi = robot.get_joint_position_limits()
    q = rng.uniform(np.maximum(lo, -2.5) * 0.9, np.minimum(hi, 2.5) * 0.9)
    v = rng.uniform(-1.5, 1.5, robot.get_nr_of_degrees_of_freedom())
    return q, v


def _frame_motion(robot, frame, q, v, eps):
    """Pose, and velocity by central finite differences of the pose along q + t v."""
    robot.set_robot_state(q + eps * v, v)
    Tp = robot.get_frame_pose(frame)
    robot.set_robot_state(q - eps * v, v)
    Tm = robot.get_frame_pose(frame)
    lin = (Tp[:3, 3] - Tm[:3, 3]) / (2 * eps)
    ang = pin.log3(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * eps)
    return np.concatenate((lin, ang))


@pytest.mark.parametrize('which,tip,base,_mid', ROBOTS)
def test_dynamics_match_pinocchio(request, rng, which, tip, base, _mid):
    robot, urdf = _load(request, which)
    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    for _ in range(3):
        q, v = _random_state(robot, rng)
        robot.set_robot_state(q, v)
        M_ref = pin.crba(model, data, q)
        M_ref = np.triu(M_ref) + np.triu(M_ref, 1).T
        np.testing.assert_allclose(robot.get_mass_matrix(), M_ref, atol=1e-12)
        np.testing.assert_allclose(
            robot.get_joint_gravity_and_coriolis_torques(),
            pin.rnea(model, data, q, v, np.zeros(model.nv)),
            atol=1e-10,
        )
        g_ref = pin.computeGeneralizedGravity(model, data, q)
        np.testing.assert_allclose(robot.get_joint_gravity_torques(), g_ref, atol=1e-10)
        C = pin.computeCoriolisMatrix(model, data, q, v)
        np.testing.assert_allclose(robot.get_joint_coriolis_torques(), C @ v, atol=1e-9)
        # frame pose in the base frame, from Pinocchio's forward kinematics
        pin.framesForwardKinematics(model, data, q)
        oMb = data.oMf[model.getFrameId(base)]
        oMf = data.oMf[model.getFrameId(tip)]
        np.testing.assert_allclose(
            robot.get_frame_pose(tip), (oMb.inverse() * oMf).homogeneous, atol=1e-12
        )


@pytest.mark.parametrize('which,tip,base,mid', ROBOTS)
@pytest.mark.parametrize('reference', ['root', 'world', 'moving'])
def test_jacobian_and_bias_acceleration_by_finite_differences(
    request, rng, which, tip, base, mid, reference
):
    robot, _ = _load(request, which)
    ref = {'root': base, 'world': 'world', 'moving': mid}[reference]
    robot.set_base_frame(ref)
    eps = 1e-6
    for _ in range(3):
        q, v = _random_state(robot, rng)
        robot.set_robot_state(q, v)
        J = robot.get_frame_jacobian(tip)
        bias = robot.get_frame_bias_acceleration(tip)
        vel = robot.get_frame_velocity(tip)
        np.testing.assert_allclose(vel, J @ v, atol=1e-12)
        # velocity: derivative of the pose along q + t v
        np.testing.assert_allclose(J @ v, _frame_motion(robot, tip, q, v, eps), atol=1e-7)
        # bias acceleration: derivative of the frame velocity along q + t v (zero joint
        # acceleration)
        robot.set_robot_state(q + eps * v, v)
        vp = robot.get_frame_velocity(tip)
        robot.set_robot_state(q - eps * v, v)
        vm = robot.get_frame_velocity(tip)
        np.testing.assert_allclose(bias, (vp - vm) / (2 * eps), atol=2e-6)
        assert np.abs(bias).max() > 0 and np.abs(J).max() > 0.1, (bias, J.shape)
        # a non-zero acceleration: d/dt (J v) = J a + J_dot v along q(t) with v(t) = v + t a
        a = rng.uniform(-1, 1, len(q))
        robot.set_robot_state(q, v)
        J0, b0 = robot.get_frame_jacobian(tip), robot.get_frame_bias_acceleration(tip)
        robot.set_robot_state(q + eps * v + 0.5 * eps**2 * a, v + eps * a)
        vp = robot.get_frame_velocity(tip)
        robot.set_robot_state(q - eps * v + 0.5 * eps**2 * a, v - eps * a)
        vm = robot.get_frame_velocity(tip)
        np.testing.assert_allclose(J0 @ a + b0, (vp - vm) / (2 * eps), atol=5e-6)


def test_relative_frames_match_base_frame_api(lwr_urdf, rng):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    q, v = _random_state(robot, rng)
    robot.set_robot_state(q, v)
    robot.set_base_frame('link_2')
    expected = (
        robot.get_frame_pose('link_6'),
        robot.get_frame_jacobian('link_6'),
        robot.get_frame_velocity('link_6'),
        robot.get_frame_bias_acceleration('link_6'),
    )
    got = (
        robot.get_relative_transform('link_2', 'link_6'),
        robot.get_relative_jacobian('link_2', 'link_6'),
        robot.get_relative_velocity('link_2', 'link_6'),
        robot.get_relative_bias_acceleration('link_2', 'link_6'),
    )
    for e, g in zip(expected, got):
        np.testing.assert_allclose(g, e, atol=1e-12)


def test_limits_read_from_urdf(lwr_urdf):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    assert robot.get_joint_names() == [f'joint_{i}' for i in range(7)]
    lo, hi = robot.get_joint_position_limits()
    np.testing.assert_allclose(hi, np.radians([170, 120, 170, 120, 170, 120, 170]), atol=1e-4)
    np.testing.assert_allclose(lo, -hi)
    np.testing.assert_allclose(robot.get_joint_torque_limits(), [176, 176, 100, 100, 100, 38, 38])
    np.testing.assert_allclose(
        robot.get_joint_velocity_limits(),
        np.radians([110, 110, 128, 128, 204, 184, 184]),
        atol=1e-4,
    )


def test_urdf_inertias_are_physically_valid(lwr_urdf):
    model = pin.buildModelFromUrdf(lwr_urdf)
    for inertia in model.inertias[1:]:
        assert inertia.mass > 0
        eig = np.linalg.eigvalsh(inertia.inertia)
        assert np.all(eig > 0)
        a, b, c = eig
        assert (
            a + b >= c - 1e-12 and a + c >= b - 1e-12 and b + c >= a - 1e-12
        )  # triangle inequality


def test_fixed_base_arm_has_gravity_in_its_dynamics(lwr_urdf):
    """
    The fixed base is first-class.

    A horizontal arm needs large shoulder torque to hold still.
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    q = np.zeros(7)
    q[1] = np.pi / 2
    robot.set_robot_state(q, np.zeros(7))
    assert robot.get_configuration_space_dimension() == 7
    assert abs(robot.get_joint_gravity_torques()[1]) > 50.0


def test_floating_base_state_layout(lwr_urdf, rng):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf, floating_base=True)
    assert (
        robot.get_configuration_space_dimension() == 13
        and robot.get_nr_of_degrees_of_freedom() == 7
    )
    T = orca.make_transform([0.1, -0.2, 0.5], orca.rotation_from_rpy(0.1, 0.2, 0.3))
    twist = np.array([0.1, 0.0, -0.2, 0.3, 0.1, 0.0])
    q, v = _random_state(robot, rng)
    robot.set_robot_state(T, q, twist, v, np.array([0, 0, -9.81]))
    robot.set_base_frame('world')
    # the root link's pose and velocity in the world are the given ones
    np.testing.assert_allclose(robot.get_frame_pose('base_link'), T, atol=1e-12)
    np.testing.assert_allclose(robot.get_frame_velocity('base_link'), twist, atol=1e-12)
    assert robot.get_mass_matrix().shape == (13, 13)
    with pytest.raises(ValueError, match='floating-base'):
        robot.set_robot_state(q, v)


def test_bad_inputs_raise_clear_errors(lwr_urdf):
    robot = orca.RobotModel()
    with pytest.raises(FileNotFoundError, match='no_such.urdf'):
        robot.load_model_from_file('/tmp/no_such.urdf')
    with pytest.raises(ValueError, match='URDF'):
        robot.load_model_from_string('<not-a-robot/>')
    with pytest.raises(RuntimeError, match='no model loaded'):
        robot.get_mass_matrix()
    robot.load_model_from_file(lwr_urdf)
    with pytest.raises(RuntimeError, match='set_robot_state'):
        robot.get_mass_matrix()
    with pytest.raises(ValueError, match=r'joint positions: expected shape \(7,\)'):
        robot.set_robot_state(np.zeros(6), np.zeros(7))
    with pytest.raises(ValueError, match='joint velocities: contains NaN'):
        robot.set_robot_state(np.zeros(7), np.array([0, 0, np.nan, 0, 0, 0, 0]))
    robot.set_robot_state(np.zeros(7), np.zeros(7))
    with pytest.raises(ValueError, match="unknown frame 'link_99'"):
        robot.get_frame_pose('link_99')
    with pytest.raises(ValueError, match="unknown frame 'flange'"):
        robot.set_base_frame('flange')
    with pytest.raises(ValueError, match='gravity'):
        robot.set_gravity([0, 0])


def test_gravity_query_does_not_corrupt_frame_terms(lwr_urdf, rng):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    q, v = _random_state(robot, rng)
    robot.set_robot_state(q, v)
    robot.get_joint_gravity_torques()  # before any frame query of this state
    b1 = robot.get_frame_bias_acceleration('link_5')
    fresh = orca.RobotModel()
    fresh.load_model_from_file(lwr_urdf)
    fresh.set_robot_state(q, v)
    np.testing.assert_allclose(b1, fresh.get_frame_bias_acceleration('link_5'), atol=1e-12)


def test_com_terms_by_finite_differences_on_a_floating_base(talos_standing, rng):
    """Check the CoM terms on Talos: J v = d/dt c, bias = d/dt (J v) (finite differences)."""
    robot, q0 = talos_standing()
    model = robot.model
    eps = 1e-6

    def com_at(q, v):
        robot.set_configuration(q, v)
        robot.get_frame_pose('torso_2_link')  # a frame query between states changes nothing
        return robot.get_center_of_mass_terms()

    for _ in range(3):
        q = pin.integrate(model, q0, rng.uniform(-0.2, 0.2, model.nv))
        v = rng.uniform(-1.0, 1.0, model.nv)
        p, J, vel, bias = (np.array(x) for x in com_at(q, v))
        np.testing.assert_allclose(vel, J @ v, atol=1e-12)
        pp = com_at(pin.integrate(model, q, eps * v), v)[0]
        pm = com_at(pin.integrate(model, q, -eps * v), v)[0]
        np.testing.assert_allclose(J @ v, (pp - pm) / (2 * eps), atol=1e-7)
        vp = com_at(pin.integrate(model, q, eps * v), v)[2]
        vm = com_at(pin.integrate(model, q, -eps * v), v)[2]
        np.testing.assert_allclose(bias, (vp - vm) / (2 * eps), atol=2e-6)
        assert np.abs(bias).max() > 0 and np.abs(J).max() > 0.1, (bias, J.shape)
