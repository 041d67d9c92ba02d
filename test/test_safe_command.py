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
"""The safe command fades from the last command into a stable, damped gravity hold."""

import numpy as np
import orca_ros as orca
from orca_ros.safety import SafeCommand
from orca_ros.sim import SimServer


def test_fade_is_continuous_and_ends_in_gravity_hold(lwr_urdf):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    safe = SafeCommand(robot, damping=10.0, ramp=0.2)
    q = np.array([0.1, 0.7, 0.0, -1.0, 0.2, 0.5, 0.0])
    last = np.full(7, 20.0)
    cmds = [safe.compute(0.001 * k, last, q, np.zeros(7)) for k in range(300)]
    steps = np.abs(np.diff(np.array([last] + cmds), axis=0)).max()
    assert steps < 20.0 * 0.001 / 0.2 * 20  # linear fade: bounded step per cycle
    robot.set_robot_state(q, np.zeros(7))
    np.testing.assert_allclose(cmds[-1], robot.get_joint_gravity_torques(), atol=1e-9)


def test_damped_hold_stops_a_moving_arm_in_simulation(lwr_urdf):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    safe = SafeCommand(robot, damping=10.0, ramp=0.0)
    with SimServer() as server:
        model = server.insert_model_from_urdf_file(lwr_urdf)
        q0 = np.array([0.1, 0.7, 0.0, -1.0, 0.2, 0.5, 0.0])
        for j, (jid, q) in enumerate(zip(model._joint_ids, q0)):
            server.client.resetJointState(model.body, jid, q, 1.0)  # every joint moving at 1 rad/s
        model._read_joints()
        for k in range(1000):
            tau = safe.compute(
                k * 0.001, np.zeros(7), model.get_joint_positions(), model.get_joint_velocities()
            )
            model.set_joint_torque_command(tau)
            server.step()
        # every joint, the light wrist included, has come to rest without oscillating away
        assert np.abs(model.get_joint_velocities()).max() < 1e-3
        assert np.abs(model.get_joint_positions() - q0).max() < 0.2
