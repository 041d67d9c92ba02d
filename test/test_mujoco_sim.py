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
The MuJoCo world keeps the PyBullet world's contract.

The same robot moves the same under the same commands, a floating base lands and stands on its
contacts, brakes and servos hold.
"""

import os
import subprocess
import sys

import numpy as np
import orca_ros as orca
from orca_ros.sim import SimServer
import pinocchio as pin
import pytest

mujoco_server = pytest.importorskip('orca_ros.sim.mujoco_server')
MujocoServer = mujoco_server.MujocoServer

DT = 0.001
Q0 = np.array([0.3, 0.5, -0.2, -1.0, 0.1, 0.6, 0.0])  # the lwr, away from its joint limits


def _gravity_model(urdf, floating=False):
    model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer()) if floating \
        else pin.buildModelFromUrdf(urdf)
    return model, model.createData()


def _wobble(t, n):
    """Accelerations [rad/s^2] that move every joint by a few centiradians over a second."""
    k = np.arange(1, n + 1)
    return np.sin(2.0 * np.pi * (0.7 + 0.3 * k) * t + k)


def test_the_same_arm_under_the_same_torques_moves_as_in_pybullet_and_pinocchio():
    """
    The lwr for 1 s under gravity compensation plus a wobble, fixed base, 1 ms steps.

    The two simulators and Pinocchio's ``aba`` with the same semi-implicit Euler step integrate
    one model with one scheme: they differ by the rounding of three dynamics algorithms (about
    1e-15 relative in each step's acceleration), accumulated over 1000 steps. 1e-9 rad leaves
    that growth four orders of magnitude; a modelling difference (the URDF's damping kept, a
    massless link given 1 kg, a joint stop) is 1e-4 rad and more.
    """
    urdf = orca.default_urdf_path()
    model, data = _gravity_model(urdf)
    names = [model.names[j] for j in range(1, model.njoints)]
    inertia = pin.crba(model, data, Q0)
    inertia = np.triu(inertia) + np.triu(inertia, 1).T
    runs = {}
    for world in (SimServer(), MujocoServer()):
        robot = world.insert_model_from_urdf_file(urdf)
        jm = robot.joint_map(names)
        robot.set_model_configuration(names, Q0)
        track = []
        for k in range(1000):
            q = robot.get_joint_positions(jm)
            tau = pin.computeGeneralizedGravity(model, data, q) + inertia @ _wobble(k * DT, 7)
            robot.set_joint_torque_command(tau, jm)
            world.step()
            track.append(np.concatenate((robot.get_joint_positions(jm),
                                         robot.get_joint_velocities(jm))))
        runs[type(world).__name__] = np.array(track)
        world.shutdown()
    q, v, track = Q0.copy(), np.zeros(model.nv), []
    for k in range(1000):
        tau = pin.computeGeneralizedGravity(model, data, q) + inertia @ _wobble(k * DT, 7)
        v = v + pin.aba(model, data, q, v, tau) * DT
        q = pin.integrate(model, q, v * DT)
        track.append(np.concatenate((q, v)))
    reference = np.array(track)
    moved = np.abs(reference[:, :7] - Q0).max()
    gaps = {w: np.abs(run - reference).max() for w, run in runs.items()}
    print(f'moved {moved:.3f} rad; largest difference from Pinocchio: {gaps}')
    assert 0.01 < moved < 0.2  # the wobble did move the arm, away from its joint limits
    assert gaps['MujocoServer'] < 1e-9 and gaps['SimServer'] < 1e-9, gaps


def test_a_floating_quadruped_in_the_air_moves_as_in_pybullet(example_robot_urdf):
    """
    Solo12 falling freely for 0.3 s, its joints wobbled: base pose and joints as in PyBullet.

    The two worlds integrate a free body differently (MuJoCo: the base link frame, its angular
    velocity in the base frame; PyBullet: the centre of mass), a difference of order
    dt^2 |w| |v| per step: with |w| about 1 rad/s and |v| up to 3 m/s, 1000 steps of 1 ms stay
    under 1e-6 m of position (and the joints, driven by the same torques, with them).
    """
    urdf = example_robot_urdf('solo_description/robots/solo12.urdf')
    model, data = _gravity_model(urdf, floating=True)
    names = [model.names[j] for j in range(2, model.njoints)]
    q0 = np.tile([0.0, 0.8, -1.6], 4)
    legs = np.diag(pin.crba(model, data, np.concatenate(([0, 0, 1, 0, 0, 0, 1], q0))))[6:]
    runs = {}
    for world in (SimServer(ground_plane=False), MujocoServer(ground_plane=False)):
        robot = world.insert_model_from_urdf_file(urdf, (0.0, 0.0, 1.0), fixed_base=False)
        jm = robot.joint_map(names)
        robot.set_model_configuration(names, q0)
        track = []
        for k in range(300):
            robot.set_joint_torque_command(legs * _wobble(k * DT, 12), jm)
            world.step()
            T = robot.get_world_to_base_transform()
            track.append(np.concatenate((T[:3, 3], T[:3, :3].ravel(),
                                         robot.get_joint_positions(jm))))
        runs[type(world).__name__] = np.array(track)
        world.shutdown()
    fell = runs['SimServer'][0, 2] - runs['SimServer'][-1, 2]
    gap = np.abs(runs['SimServer'] - runs['MujocoServer']).max()
    print(f'fell {fell:.3f} m; largest difference {gap:.2e}')
    assert fell > 0.4  # 1/2 g t^2 = 0.44 m
    assert gap < 1e-6


def test_a_quadruped_dropped_on_the_ground_stands_on_its_four_feet(example_robot_urdf):
    """
    Drop Solo12 from 0.3 m, its joints held by a PD (10 Nm/rad, 0.5 Nm s/rad).

    2 s later the four feet carry its weight (the ground's force on them within 0.5 % of m g:
    it is at rest, and its measured base speed bounds what the accelerations still take) and
    nothing else touches.
    """
    urdf = example_robot_urdf('solo_description/robots/solo12.urdf')
    model, data = _gravity_model(urdf, floating=True)
    names = [model.names[j] for j in range(2, model.njoints)]
    q0 = np.tile([0.0, 0.8, -1.6], 4)
    feet = ['FL_FOOT', 'FR_FOOT', 'HL_FOOT', 'HR_FOOT']
    world = MujocoServer()
    robot = world.insert_model_from_urdf_file(urdf, (0.0, 0.0, 0.3), fixed_base=False)
    jm = robot.joint_map(names)
    robot.set_model_configuration(names, q0)
    for _ in range(2000):
        q, v = robot.get_joint_positions(jm), robot.get_joint_velocities(jm)
        robot.set_joint_torque_command(10.0 * (q0 - q) - 0.5 * v, jm)
        world.step()
    contacts = robot.get_contacts()
    weight = pin.computeTotalMass(model) * 9.81
    carried = sum(c.force[2] for c in contacts)
    speed = np.abs(robot.get_base_velocity()).max()
    height = robot.get_world_to_base_transform()[2, 3]
    print(f'{len(contacts)} contacts on {sorted({c.link for c in contacts})}; they carry '
          f'{carried:.3f} N of {weight:.3f} N; base at {height:.4f} m, speed {speed:.1e}')
    assert {c.link for c in contacts} == set(feet)
    assert all(c.other_body == world.plane_id and c.normal[2] > 0.99 for c in contacts)
    assert speed < 1e-3
    assert abs(carried - weight) < 5e-3 * weight
    world.shutdown()


def test_brakes_and_servos_hold_the_arm():
    """
    Hold the lwr with brakes, then two of its joints with servos.

    Braked, the arm held out sideways moves less than 1 mrad in 1 s (no torque command);
    servoed, two joints stay within 1 mrad of their targets while the others are
    torque-controlled.
    """
    urdf = orca.default_urdf_path()
    world = MujocoServer()
    robot = world.insert_model_from_urdf_file(urdf)
    names = robot.get_joint_names()
    robot.set_model_configuration(names, Q0)
    robot.set_brakes(True)
    world.step(1000)
    braked = np.abs(robot.get_joint_positions() - Q0).max()
    robot.set_brakes(False)
    robot.set_model_configuration(names, Q0)
    robot.set_joint_position_servo(names[:2], Q0[:2])
    model, data = _gravity_model(urdf)
    for _ in range(1000):
        q = robot.get_joint_positions()
        robot.set_joint_torque_command(pin.computeGeneralizedGravity(model, data, q)[2:],
                                       names[2:])
        world.step()
    servoed = np.abs(robot.get_joint_positions(names[:2]) - Q0[:2]).max()
    print(f'braked: {braked:.2e} rad; servoed: {servoed:.2e} rad')
    assert robot.get_servoed_joint_names() == names[:2]
    assert braked < 1e-3 and servoed < 1e-3
    with pytest.raises(ValueError, match='needs 7 values'):
        robot.set_joint_torque_command(np.zeros(6))
    with pytest.raises(ValueError, match='NaN'):
        robot.set_joint_torque_command(np.full(7, np.nan))
    with pytest.raises(ValueError, match="no link 'nowhere'"):
        robot.get_link_position('nowhere')
    world.shutdown()


@pytest.mark.parametrize('world_class', [SimServer, MujocoServer])
def test_obstacles_are_placed_moved_measured_and_removed(world_class):
    """
    Both worlds' obstacles keep one contract (the bridges' ``~/obstacles`` rely on it).

    A ball 5 cm round clear of the lwr goes into none of its links; centred on the arm's axis at
    0.6 m it goes 115 mm into link_3 (the ball's radius plus the link's: the same geometry in both
    worlds, to 1 mm: MuJoCo's hull of the link's mesh); removing one leaves the others in place.
    """
    world = world_class()
    arm = world.insert_model_from_urdf_file(orca.default_urdf_path())
    clear, onto = np.eye(4), np.eye(4)
    clear[:3, 3], onto[:3, 3] = [0.3, 0.0, 0.5], [0.0, 0.0, 0.6]
    world.obstacles.add('ball', 'sphere', [0.05], clear)
    world.obstacles.add('box', 'box', [0.1, 0.2, 0.3], clear)
    world.obstacles.add('can', 'cylinder', [0.05, 0.2], clear)
    assert world.obstacles.depth_into('ball', arm) == (0.0, '')
    world.obstacles.move('ball', onto)
    depth, link = world.obstacles.depth_into('ball', arm)
    print(f'{world_class.__name__}: the ball {depth * 1e3:.2f} mm into {link}')
    assert link == 'link_3' and abs(depth - 0.1155) < 1e-3
    np.testing.assert_allclose(world.obstacles.pose('ball'), onto, atol=1e-12)
    world.step(5)
    world.obstacles.remove('ball')
    assert world.obstacles.names() == ['box', 'can']
    np.testing.assert_allclose(world.obstacles.pose('box'), clear, atol=1e-12)
    world.step(5)
    world.shutdown()


@pytest.mark.parametrize('world_class', [SimServer, MujocoServer])
def test_the_base_hold_holds_then_gives_way(world_class, example_robot_urdf):
    """
    Hold Solo12's base 0.5 m up, then let it go.

    1 s later its base is where placed (0.1 mm: the crane's stiffness against the legs swinging
    down); released over 0.2 s, it falls to the ground.
    """
    urdf = example_robot_urdf('solo_description/robots/solo12.urdf')
    world = world_class()
    robot = world.insert_model_from_urdf_file(urdf, (0.0, 0.0, 0.5), fixed_base=False)
    robot.set_model_configuration(robot.get_joint_names(), np.tile([0.0, 0.8, -1.6], 4))
    hold = world.hold_base(robot)
    placed = robot.get_world_to_base_transform()[:3, 3].copy()
    world.step(1000)
    held = np.linalg.norm(robot.get_world_to_base_transform()[:3, 3] - placed)
    hold.release(world.get_time(), 0.2)
    world.step(400)
    low = robot.get_world_to_base_transform()[2, 3]
    print(f'{world_class.__name__}: held {held * 1e3:.4f} mm from where placed; released, the '
          f'base at {low:.3f} m')
    assert held < 1e-4 and not hold.holding and low < 0.1
    world.shutdown()


def test_without_mujoco_one_line(tmp_path):
    """A Python without MuJoCo: ``mujoco_bridge`` says so in one line; the rest imports."""
    (tmp_path / 'mujoco.py').write_text(
        "raise ModuleNotFoundError(\"No module named 'mujoco'\", name='mujoco')\n"
    )
    env = {**os.environ, 'PYTHONPATH': str(tmp_path)}
    res = subprocess.run([sys.executable, '-m', 'orca_ros.ros.mujoco_bridge'], env=env,
                         capture_output=True, text=True, timeout=60)
    lines = [x for x in (res.stdout + res.stderr).strip().splitlines()
             if not x.startswith('pybullet build time')]  # PyBullet's own banner at import
    assert res.returncode == 1
    assert lines == ["mujoco_bridge needs the Python package 'mujoco': pip install mujoco==4.0.0"]
    res = subprocess.run(
        [sys.executable, '-c', 'import orca_ros.sim, orca_ros.ros.pybullet_bridge, '
         'orca_ros.ros.sim_bridge, orca_ros.ros.sim_obstacles'],
        env=env, capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr


def test_a_blown_up_state_is_counted_and_the_world_goes_on():
    """
    A torque no joint takes in one step: MuJoCo resets the state; the world counts it, steps on.

    (MuJoCo only warns; the bridge says so from the count.) The arm is back at its rest pose
    (q = 0, at rest) and takes commands again.
    """
    world = MujocoServer()
    arm = world.insert_model_from_urdf_file(orca.default_urdf_path())
    arm.set_model_configuration(arm.get_joint_names(), Q0)
    arm.set_joint_torque_command(np.array([0.0] * 6 + [1e12]))
    world.step()
    assert world.resets == 1 and world.last_reset == pytest.approx(DT)
    assert np.all(arm.get_joint_positions() == 0.0) and np.all(arm.get_joint_velocities() == 0.0)
    arm.set_joint_torque_command(np.array([1.0] + [0.0] * 6))
    world.step(10)
    assert world.resets == 1 and np.all(np.isfinite(arm.get_joint_positions()))
    assert arm.get_joint_positions()[0] > 0.0  # the first joint turns under its torque
    world.shutdown()
