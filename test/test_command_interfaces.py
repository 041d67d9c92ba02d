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
Command interfaces without ROS: the integrated reference, each interface's command, the drives.

orca_ros.command (what the controller sends) and orca_ros.sim.DriveModel (what a simulated drive
does with it), on the lwr of this package.
"""

import numpy as np
import orca_ros as orca
from orca_ros.command import INTERFACES, JointCommand, JointReference
from orca_ros.sim.drive_model import DriveModel
import pytest

DT = 1e-3


@pytest.fixture(scope='module')
def lwr():
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    return robot


def test_the_reference_integrates_a_constant_acceleration_exactly():
    """Followed exactly by the robot, the reference is the closed-form trajectory."""
    n = 3
    ref = JointReference(-10 * np.ones(n), 10 * np.ones(n), 100 * np.ones(n), 0.05, 0.5)
    q0, v0, a = np.array([0.1, -0.2, 0.3]), np.array([0.5, 0.0, -0.4]), np.array([1.0, -2.0, 0.5])
    q, v = q0.copy(), v0.copy()
    for k in range(1, 501):
        ref.advance(q, v, a, DT)
        q, v = ref.position.copy(), ref.velocity.copy()
        t = k * DT
        # the recurrence's rounding: a few ulps of the values per step
        tol = 8 * k * np.finfo(float).eps * (1 + np.abs(q0) + np.abs(v0) + np.abs(a))
        np.testing.assert_allclose(q, q0 + v0 * t + 0.5 * a * t * t, rtol=0, atol=tol.max())
        np.testing.assert_allclose(v, v0 + a * t, rtol=0, atol=tol.max())


def test_the_reference_is_leashed_to_a_robot_that_does_not_follow():
    """A blocked robot: the reference stays within the leash (plus one step) of it."""
    ref = JointReference([-3.0], [3.0], [10.0], position_leash=0.02, velocity_leash=0.2)
    q, v, a = np.zeros(1), np.zeros(1), np.array([5.0])
    for _ in range(2000):
        ref.advance(q, v, a, DT)
        assert abs(ref.velocity[0] - v[0]) <= 0.2 + a[0] * DT + 1e-12
        assert abs(ref.position[0] - q[0]) <= 0.02 + (0.2 + a[0] * DT) * DT + 1e-12
    assert ref.position[0] > 0.02  # it did pull as far as the leash lets it


def test_the_reference_holds_the_joint_limits():
    """Accelerations far beyond the limits: the reference stops on them, never past them."""
    ref = JointReference([-1.0, -2.0], [1.0, 2.0], [0.5, 0.0], 10.0, 10.0)  # 0: no limit
    q, v = np.zeros(2), np.zeros(2)
    for k in range(5000):
        ref.advance(q, v, np.array([50.0, -50.0]), DT)
        q, v = ref.position.copy(), ref.velocity.copy()
        assert -1.0 <= q[0] <= 1.0 and -2.0 <= q[1] <= 2.0
        assert abs(v[0]) <= 0.5
    assert q[0] == 1.0 and v[0] == 0.0 and q[1] == -2.0 and v[1] == 0.0


def test_joint_impedance_applies_the_qp_torque_at_the_measured_state(lwr):
    """tau_ff + K_p (q_r - q) + K_d (v_r - v) = tau, the drive's torque where the QP solved."""
    kp, kd = np.linspace(100.0, 700.0, 7), np.full(7, 5.0)
    cmd = JointCommand('joint_impedance', lwr, kp, kd)
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-1, 1, 7), rng.normal(0, 0.5, 7)
    for _ in range(50):
        tau, a = rng.normal(0, 20, 7), rng.normal(0, 3, 7)
        values = cmd.solved(q, v, tau, a, DT)
        p, w, ff, s, d = values
        assert np.array_equal(s, kp) and np.array_equal(d, kd)
        drive = ff + s * (p - q) + d * (w - v)
        np.testing.assert_allclose(drive, tau, rtol=0, atol=1e-12 * (1 + np.abs(tau).max()))
        q, v = q + DT * v + rng.normal(0, 1e-4, 7), v + rng.normal(0, 1e-3, 7)


def test_each_interface_sends_its_fields_and_holds(lwr):
    """Effort: the torque; the others: the reference; a hold stops it where it was."""
    q, v = np.full(7, 0.2), np.full(7, 0.1)
    tau, a, hold = np.arange(7.0), np.ones(7), -np.arange(7.0)
    for name, fields in INTERFACES.items():
        gains = {'stiffness': 300.0, 'damping': 10.0} if name == 'joint_impedance' else {}
        cmd = JointCommand(name, lwr, **gains)
        assert cmd.fields == fields
        values = cmd.solved(q, v, tau, a, DT)
        assert values.shape == (len(fields), 7)
        if name == 'effort':
            assert np.array_equal(values[0], tau)
            assert np.array_equal(cmd.held(q, hold)[0], hold)
            continue
        position = q + DT * v + 0.5 * DT * DT * a
        if 'position' in fields:
            np.testing.assert_allclose(cmd.field('position'), position, rtol=0, atol=1e-15)
        if 'velocity' in fields:
            np.testing.assert_allclose(cmd.field('velocity'), v + DT * a, rtol=0, atol=1e-15)
        held = cmd.held(q + 0.01, hold).copy()
        if 'position' in fields:  # stopped where the reference was, not at the new state
            np.testing.assert_allclose(held[fields.index('position')], position, atol=1e-15)
        if 'velocity' in fields:
            assert not held[fields.index('velocity')].any()
        if name == 'joint_impedance':
            assert np.array_equal(held[fields.index('effort')], hold)
        # after the hold the reference starts from the measured state again
        cmd.solved(q + 0.03, np.zeros(7), tau, np.zeros(7), DT)
        if 'position' in fields:
            np.testing.assert_allclose(cmd.field('position'), q + 0.03, atol=1e-15)


def test_bad_interfaces_and_gains_are_refused_with_the_cause(lwr):
    with pytest.raises(ValueError, match="'torque' is not one of effort, position"):
        JointCommand('torque', lwr)
    with pytest.raises(ValueError, match='needs joint_stiffness and joint_damping'):
        JointCommand('joint_impedance', lwr, stiffness=100.0)
    with pytest.raises(ValueError, match='joint_stiffness must be finite and >= 0'):
        JointCommand('joint_impedance', lwr, stiffness=[100.0] * 6 + [-1.0], damping=1.0)
    with pytest.raises(ValueError, match='joint_damping: 3 values for 7 joints'):
        JointCommand('joint_impedance', lwr, stiffness=100.0, damping=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match='position_leash must be finite and > 0'):
        JointCommand('position', lwr, position_leash=0.0)


def test_a_position_drive_is_a_critically_damped_servo():
    """
    A joint of inertia m behind a position drive at f Hz: x(t) = x_r (1 - (1 + w t) e^(-w t)).

    Integrated at 10 kHz (semi-implicit Euler); the error bound is the scheme's, O(w dt) of
    the step.
    """
    m, f, step = 0.7, 20.0, 0.01
    drive = DriveModel('position', [m], [1e3], servo_frequency=f)
    w = 2 * np.pi * f
    assert drive.servo_stiffness[0] == pytest.approx(m * w * w)
    assert drive.servo_damping[0] == pytest.approx(2 * m * w)
    drive.set_command([[step]])
    x, xd, h = 0.0, 0.0, 1e-4
    worst = 0.0
    for k in range(1, 3001):
        xd += h * drive.torque(np.array([x]), np.array([xd]), np.zeros(1))[0] / m
        x += h * xd
        t = k * h
        worst = max(worst, abs(x - step * (1 - (1 + w * t) * np.exp(-w * t))))
        assert x <= step * (1 + 1e-9)  # no overshoot
    assert worst <= 2 * w * h * step


def test_drives_clip_to_their_effort_limits_and_refuse_bad_commands():
    drive = DriveModel('joint_impedance', [1.0, 1.0], [10.0, 0.0])  # 0: no limit
    drive.set_command([[1.0, 1.0], [0.0, 0.0], [5.0, 5.0], [100.0, 100.0], [1.0, 1.0]])
    tau = drive.torque(np.zeros(2), np.zeros(2), np.zeros(2))
    assert tau.tolist() == [10.0, 105.0]
    # the hold: the last position kept, velocity reference 0, gravity as the feed-forward
    tau = drive.torque(np.zeros(2), np.array([1.0, 1.0]), np.array([2.0, 2.0]), hold=True)
    assert tau.tolist() == [10.0, 2.0 + 100.0 - 1.0]
    with pytest.raises(ValueError, match=r'3 values for 5 field\(s\)'):
        drive.set_command([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match='negative stiffness or damping'):
        drive.set_command([[1.0, 1.0], [0.0, 0.0], [5.0, 5.0], [-1.0, 100.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match='non-finite'):
        drive.set_command([[np.nan, 1.0], [0.0, 0.0], [5.0, 5.0], [1.0, 100.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match="command_interface 'mit' is not one of"):
        DriveModel('mit', [1.0], [1.0])


def test_the_arms_position_servos_are_critically_damped_at_every_posture(lwr):
    """
    The lwr in PyBullet behind the simulated position servos (the bridge's law, M at each step).

    Every joint answers a step of its reference as x_r (1 - (1 + w t) e^(-w t)), w = 2 pi 20 Hz,
    independently of the others, at the start posture and stretched upright (where the first
    joint's inertia with the others free is 11x smaller). Effort limits left out (a 0.05 rad step
    asks up to 1.6 kNm at the first instant); the bound is the explicit step's, O(w dt) of the
    step (as the 1-DoF servo's above), plus the motion's Coriolis torques, left out by the law.
    Independent PDs on each joint's inertia 1 / (M^-1)_ii instead: the first joint 5x slower.
    """
    from orca_ros.ros.testing.launch_free import ARM_Q0
    from orca_ros.sim import SimServer

    w, h = 2 * np.pi * 20.0, 1e-3
    names = lwr.get_joint_names()
    step = np.array([0.05, 0.05, -0.05, 0.05, 0.05, -0.05, 0.05])
    for q0 in (np.array(ARM_Q0, dtype=float), np.zeros(7)):
        with SimServer(time_step=h) as server:
            sim = server.insert_model_from_urdf_file(orca.default_urdf_path())
            sim.set_model_configuration(names, q0)
            lwr.set_robot_state(q0, np.zeros(7))
            inertia = 1.0 / np.diag(np.linalg.inv(lwr.get_mass_matrix()))
            drive = DriveModel('position', inertia, np.zeros(7), servo_frequency=20.0)
            drive.set_command((q0 + step)[None])
            worst = 0.0
            for k in range(300):
                q, v = sim.get_joint_positions(names), sim.get_joint_velocities(names)
                ideal = step * (1 - (1 + w * k * h) * np.exp(-w * k * h))
                worst = max(worst, np.abs(q - q0 - ideal).max())
                lwr.set_robot_state(q, v)
                tau = drive.torque(q, v, lwr.get_joint_gravity_torques(),
                                   mass=lwr.get_mass_matrix())
                sim.set_joint_torque_command(tau, names)
                server.step()
            print(f'from {q0.round(2).tolist()}: {worst:.2e} rad from the ideal servo at worst')
            assert worst <= 2 * w * h * np.abs(step).max()
            assert np.abs(q - q0 - step).max() < 1e-6


def _lwr_config(**changes):
    """Return config/lwr_controller.yaml's parameters without the torque limit, changed."""
    import yaml

    with open(orca.share_path('config', 'lwr_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    cfg['constraints']['names'] = ['position_limit', 'velocity_limit']
    cfg.update(changes)
    return cfg


def _accelerations(cfg, seconds=1.5):
    """Run the hand 10 cm along x on a perfect position drive: accelerations, torques, error."""
    from orca_ros.configuration import build_from_config
    from orca_ros.ros.testing.launch_free import ARM_Q0

    setup = build_from_config(cfg)
    c, robot = setup.controller, setup.robot
    c.activate_tasks_and_constraints()
    q, v = np.array(ARM_Q0, dtype=float), np.zeros(7)
    robot.set_robot_state(q, v)
    servo = c.get_task('ee').servo_controller()
    target = servo.get_current_cartesian_pose().copy()
    target[:3, 3] += [0.1, 0.0, 0.0]
    servo.set_desired(target)
    acc, tau = [], []
    for k in range(int(round(seconds / DT))):
        robot.set_robot_state(q, v)
        assert c.update(k * DT, DT)
        acc.append(c.get_joint_acceleration_command().copy())
        tau.append(c.get_joint_torque_command().copy())
        q, v = q + DT * v + 0.5 * DT * DT * acc[-1], v + DT * acc[-1]
    robot.set_robot_state(q, v)
    error = np.linalg.norm(robot.get_frame_pose('link_7')[:3, 3] - target[:3, 3])
    return np.array(acc), np.array(tau), error


def test_the_kinematic_formulation_needs_no_dynamics_model(tmp_path):
    """
    ``kinematic: true``: the model's inertias dropped, the same accelerations, no torques.

    The lwr's URDF without a single <inertial> element (nothing known of its dynamics), kinematic:
    the same joint accelerations, cycle after cycle, as the dynamic formulation on the full model
    (no torque rows: its tasks are accelerations; the two differ by round-off at most), every
    torque zero, the target reached. What needs the dynamics is refused, named.
    """
    import re

    from orca_ros.configuration import build_from_config, ConfigError

    with open(orca.default_urdf_path()) as fh:
        text = re.sub(r'<inertial>.*?</inertial>', '', fh.read(), flags=re.S)
    assert '<inertial>' not in text
    bare = tmp_path / 'lwr_without_inertias.urdf'
    bare.write_text(text)
    acc, tau, error = _accelerations(_lwr_config(urdf_path=str(bare), kinematic=True))
    full_acc, full_tau, _ = _accelerations(_lwr_config())
    gap = np.abs(acc - full_acc).max()
    print(f'kinematic on no inertias: {gap:.1e} rad/s^2 from the dynamic formulation '
          f'(accelerations up to {np.abs(acc).max():.1f}); hand {error * 1e3:.2e} mm from the '
          f'target; torques up to {np.abs(tau).max()} (dynamic: {np.abs(full_tau).max():.1f})')
    assert gap <= 1e-9 * np.abs(full_acc).max()
    assert not tau.any() and error < 1e-3
    torque_limit = {'names': ['torque_limit'], 'torque_limit': {'type': 'joint_torque_limit'}}
    for change, said in (
        ({'floating_base': True}, 'a fixed base only'),
        ({'constraints': torque_limit}, "'torque_limit' (joint_torque_limit)"),
        ({'tasks': {'names': ['com'], 'com': {'type': 'com'}}}, "task 'com' (com) needs"),
    ):
        with pytest.raises(ConfigError, match=re.escape(said)):
            build_from_config(_lwr_config(kinematic=True, **change))
