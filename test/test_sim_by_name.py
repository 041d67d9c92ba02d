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
The simulation layer addressed by joint names, its friction setting and its contact readout.

Ghost Robotics' Spirit 40 of ``pybullet_data``: declared FR, FL, RR, RL, so PyBullet's joint order
(the file's) is not Pinocchio's (FL, FR, RL, RR: subtrees sorted by joint name).
"""

import os

import numpy as np
import orca_ros as orca
from orca_ros.sim import SimServer
import pybullet_data
import pytest

SPIRIT = os.path.join(pybullet_data.getDataPath(), 'quadruped', 'spirit40newer.urdf')
FEET = [f'{leg}_toe' for leg in ('FR', 'FL', 'RR', 'RL')]


def _stance(names):
    return np.array([0.0 if 'hip' in n else (-0.8 if 'upper' in n else 1.6) for n in names])


def _posture_controller(robot, target):
    c = orca.Controller('posture', robot, orca.ResolutionStrategy.ONE_LEVEL_WEIGHTED)
    task = c.add_task(orca.JointAccelerationTask, 'posture')
    task.pid().set_proportional_gain(np.full(robot.get_nr_of_degrees_of_freedom(), 400.0))
    task.pid().set_derivative_gain(np.full(robot.get_nr_of_degrees_of_freedom(), 40.0))
    task.pid().set_integral_gain(np.full(robot.get_nr_of_degrees_of_freedom(), 200.0))
    task.set_desired(target)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torques')
    c.activate_tasks_and_constraints()
    return c


def _run_posture(by_name: bool, seconds: float = 2.0):
    """Each joint of a fixed-base Spirit to its own target; torques sent by name or by position."""
    robot = orca.RobotModel()
    robot.load_model_from_file(SPIRIT)
    names = robot.get_joint_names()
    target = _stance(names) + 0.05 * np.arange(len(names)) / len(names)
    controller = _posture_controller(robot, target)
    with SimServer(ground_plane=False) as server:
        sim = server.insert_model_from_urdf_file(SPIRIT, (0, 0, 1.0), fixed_base=True)
        assert sim.get_joint_names() != names, 'this robot must show the two orders differing'
        to_sim = sim.joint_map(names)
        sim.set_model_configuration(names, _stance(names))
        t, dt = 0.0, server.time_step
        while t < seconds:
            robot.set_robot_state(
                sim.get_joint_positions(to_sim), sim.get_joint_velocities(to_sim)
            )
            assert controller.update(t, dt)
            tau = controller.get_joint_torque_command()
            if by_name:
                sim.set_joint_torque_command(tau, to_sim)
            else:  # the trap: an array in Pinocchio's order passed as if it were PyBullet's
                sim.set_joint_torque_command(tau)
            server.step()
            t += dt
        return sim.get_joint_positions(names) - target, names


def test_by_name_torques_reach_each_joints_own_target():
    err, names = _run_posture(by_name=True)
    worst = int(np.argmax(np.abs(err)))
    assert np.abs(err).max() < 5e-3, f'{names[worst]} {err[worst]:.4f} rad from its target'


def test_positional_torques_on_this_robot_go_to_the_wrong_joints():
    """What the by-name API prevents: the same loop with a positional array misses the targets."""
    err, _ = _run_posture(by_name=False, seconds=0.5)
    assert np.abs(err).max() > 0.1


def test_joint_map_round_trip_and_refusals():
    with SimServer(ground_plane=False) as server:
        sim = server.insert_model_from_urdf_file(SPIRIT)
        names = sorted(sim.get_joint_names())
        m = sim.joint_map(names)
        x = np.arange(len(names), dtype=float)
        np.testing.assert_array_equal(m.from_sim(m.to_sim(x)), x)
        assert [sim.get_joint_names()[i] for i in m.sim_index] == names
        with pytest.raises(ValueError, match=r"no joint\(s\) \['FR_knee'\]"):
            sim.joint_map(['FR_knee'])
        with pytest.raises(ValueError, match='listed twice'):
            sim.joint_map(names[:2] + names[:1])
        with pytest.raises(ValueError, match='needs 2 values'):
            sim.set_joint_torque_command([1.0, 2.0, 3.0], names[:2])
        sim.set_joint_torque_command([1.5], ['RL_lower_joint'])
        server.step()
        applied = sim.get_joint_measured_torques()
        assert applied[sim.get_joint_names().index('RL_lower_joint')] == 1.5
        assert np.count_nonzero(applied) == 1


def _mean_contact_forces(server, sim, steps=200):
    """Mean over ``steps`` steps: total, normal, friction force, and the feet's forces summed."""
    acc = [np.zeros(3), 0.0, np.zeros(3), np.zeros(3)]
    for _ in range(steps):
        server.step()
        contacts = sim.get_contacts()
        acc[0] += sum(p.force for p in contacts) / steps
        acc[1] += sum(p.normal_force for p in contacts) / steps
        acc[2] += sum(p.friction_force for p in contacts) / steps
        acc[3] += sum(sim.get_contact_force(f) for f in FEET) / steps
    return acc


@pytest.mark.parametrize('mu, slides', [(1.0, False), (0.1, True)])
def test_friction_setting_and_contact_forces(mu, slides):
    """
    Standing Spirit (joints held by position servos), then gravity tilted by atan(0.3).

    Contacts on the four toes carry the weight; a friction coefficient above 0.3 holds the robot
    (the contact forces balance gravity, friction opposing the slope), below it the robot slides
    and friction saturates at mu times the normal force.
    """
    with SimServer() as server:
        sim = server.insert_model_from_urdf_file(SPIRIT, (0, 0, 0.35), fixed_base=False)
        names = sim.get_joint_names()
        sim.set_model_configuration(names, _stance(names))
        sim.set_joint_position_servo(names, _stance(names))
        sim.set_friction(mu, links=FEET)
        assert sim.get_friction('FR_toe')['lateral'] == pytest.approx(mu)
        c = server.client
        mass = sum(c.getDynamicsInfo(sim.body, k)[0] for k in range(-1, c.getNumJoints(sim.body)))
        server.run(1.0)
        assert {p.link for p in sim.get_contacts()} == set(FEET)
        assert all(p.normal[2] > 0.99 and p.normal_force >= 0 for p in sim.get_contacts())
        total, _, _, _ = _mean_contact_forces(server, sim)
        np.testing.assert_allclose(total, [0.0, 0.0, mass * 9.81], atol=3e-3 * mass * 9.81)
        x0 = sim.get_world_to_base_transform()[:3, 3]
        g = np.array([0.3 * 9.81, 0.0, -9.81])
        server.set_gravity(g)
        server.run(1.0)
        total, normal, friction, per_foot = _mean_contact_forces(server, sim)
        moved = np.linalg.norm(sim.get_world_to_base_transform()[:3, 3] - x0)
        assert friction[0] < 0  # opposes the slope
        if slides:
            assert moved > 0.2
            assert np.linalg.norm(friction) == pytest.approx(mu * normal, rel=0.02)
        else:
            assert moved < 1e-3
            np.testing.assert_allclose(total, -mass * g, atol=3e-3 * mass * 9.81)
            np.testing.assert_allclose(per_foot, total, atol=1e-9)
