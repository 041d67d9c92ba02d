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
The joint-state plausibility bounds change together when one request sets both (issue 40).

``position_margin`` and ``velocity_factor`` are live parameters of the controller node; both
rebuild the measured state's checks. Planned from the bounds before the request, a request
setting both kept only the last one applied. Checked in-process on the node's measured state:
after one atomic request, a joint state beyond the old margin and faster than the old factor
allows (but within the new ones) is accepted, and both bounds read back as set.
"""

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import ARM_Q0, free_domain_id


def test_both_bounds_in_one_request_both_apply():
    import rclpy
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import JointState
    from orca_ros.ros.controller_node import OrcaControllerNode
    from orca_ros.ros.measured_state import StateRejected

    params = orca.share_path('config', 'lwr_controller.yaml')
    rclpy.init(args=['--ros-args', '--params-file', params, '-p', 'trigger:=joint_state',
                     '-p', 'manage_gc:=false'], domain_id=free_domain_id())
    try:
        node = OrcaControllerNode()
        state = node.state
        margin, factor = state.joint_input.margin, state.velocity_factor
        lo, hi = node.robot.get_joint_position_limits()
        vmax = node.robot.get_joint_velocity_limits()
        k = node.setup.joints.index(node.robot.get_joint_names()[0])  # wire slot of joint 0
        q = np.array(ARM_Q0, dtype=float)
        q[k] = hi[0] + 1.5 * margin  # beyond the old margin, within 2x it
        v = np.zeros(len(q))
        v[k] = 1.5 * factor * vmax[0]  # beyond the old factor, within 2x it
        msg = JointState(name=list(node.setup.joints), position=q.tolist(), velocity=v.tolist())
        msg.header.stamp.sec = 1
        try:
            state.read_joint_state(msg)
            raise AssertionError('the state was accepted before the change')
        except StateRejected:
            pass
        result = node.set_parameters_atomically([
            Parameter('position_margin', value=2.0 * margin),
            Parameter('velocity_factor', value=2.0 * factor),
        ])
        assert result.successful, result.reason
        assert state.joint_input.margin == 2.0 * margin
        assert state.velocity_factor == 2.0 * factor
        assert state.read_joint_state(msg)  # accepted: a new instant
        assert state.q[0] == q[k] and state.v[0] == v[k]
        node.destroy_node()
    finally:
        rclpy.shutdown()
