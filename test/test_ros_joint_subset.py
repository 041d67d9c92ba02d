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
An arm with a gripper: the controller commands the 7 arm joints and leaves the fingers alone.

Franka Panda of ``pybullet_data`` (9 joints: 7 revolute, 2 prismatic fingers). The bridge takes 7
efforts and holds the fingers with the simulator's position motor (the gripper's own driver); the
controller locks the fingers in its model at the measured opening and still reaches its targets.
On either bridge (MuJoCo's: a position actuator holds the fingers).
"""

import os

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pybullet_data
import pytest

URDF = os.path.join(pybullet_data.getDataPath(), 'franka_panda', 'panda.urdf')
ARM = [f'panda_joint{i}' for i in range(1, 8)]
FINGERS = ['panda_finger_joint1', 'panda_finger_joint2']
Q0 = [0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8]
OPENING = 0.03

PARAMS = f"""orca_controller:
  ros__parameters:
    urdf_path: {URDF}
    base_frame: panda_link0
    joints: {ARM}
    trigger: joint_state
    solver: daqp
    resolution_strategy: multi_level_weighted
    diagnostics_rate: 0.0
    feedback_rate: 0.0
    tasks:
      names: [ee, posture]
      ee:
        type: cartesian
        frame: panda_grasptarget
        kp: [400.0, 400.0, 400.0, 100.0, 100.0, 100.0]
        kd: [40.0, 40.0, 40.0, 20.0, 20.0, 20.0]
      posture:
        type: joint_acceleration
        level: 1
        kp: 25.0
        kd: 10.0
        target: {Q0}
    constraints:
      names: [torque_limit, position_limit, velocity_limit]
      torque_limit:
        type: joint_torque_limit
      position_limit:
        type: joint_position_limit
        horizon: 0.05
      velocity_limit:
        type: joint_velocity_limit
        max: 1.0
"""


def _grasp_target_pose(model, q, fingers):
    model.set_robot_state(np.concatenate((q, fingers)), np.zeros(9))
    return model.get_frame_pose('panda_grasptarget')


@pytest.mark.parametrize('simulator', ['pybullet', 'mujoco'])
def test_arm_with_gripper_commands_only_the_arm_joints(tmp_path, simulator):
    params = tmp_path / 'panda.yaml'
    params.write_text(PARAMS)
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start(
        f'orca_ros.ros.{simulator}_bridge',
        '-p', f'urdf_path:={URDF}',
        '-p', 'mode:=lockstep',
        '-p', f'joints:={ARM}',
        '-p', f'initial_positions:={Q0}',
        '-p', f'held_joint_positions:={[OPENING, OPENING]}',
        name='bridge',
    )
    procs.start(
        'orca_ros.ros.controller_node', '--params-file', str(params), name='controller'
    )
    probe = Probe(domain, joints=ARM + FINGERS)
    full = orca.RobotModel()  # the whole arm, fingers included: what the simulator moves
    full.load_model_from_file(URDF)
    full.set_base_frame('panda_link0')
    try:
        probe.wait_for(lambda: probe.sim_time() > 1.0, 120, 'the controller driving the bridge')
        log = procs.log('controller')
        assert f'7 joints (locked: {FINGERS})' in log, log[-2000:]

        def pose():
            q = probe.last_state()[1]
            return _grasp_target_pose(full, q[:7], q[7:])

        start = pose()
        target = start.copy()
        target[:3, 3] += [0.10, -0.08, -0.06]
        direction = (target[:3, 3] - start[:3, 3]) / np.linalg.norm(target[:3, 3] - start[:3, 3])
        pub = probe.node.create_publisher(
            probe.PoseStamped, '/orca_controller/tasks/ee/target_pose', 10
        )
        from orca_ros.ros.common import matrix_to_pose

        msg = probe.PoseStamped()
        matrix_to_pose(target, msg.pose)
        probe.publish_until(
            lambda: pub.publish(msg),
            lambda: (pose()[:3, 3] - start[:3, 3]) @ direction > 2e-3,
            'the grasp target moving towards its target',
        )
        probe.wait_sim(4.0, timeout=300)
        err = np.linalg.norm(pose()[:3, 3] - target[:3, 3])
        assert err < 2e-3, f'grasp target {err * 1e3:.2f} mm from its target'
        with probe.lock:
            commands = list(probe.commands)
        assert commands, 'no command recorded'
        assert {c.size for c in commands} == {7}, 'the controller must command the 7 arm joints'
        assert all(np.isfinite(c).all() for c in commands)
        fingers = probe.last_state()[1][7:]
        np.testing.assert_allclose(fingers, OPENING, atol=2e-3)  # left to their own driver
        assert 'Traceback' not in procs.log('controller')
    finally:
        probe.close()
        procs.stop()
