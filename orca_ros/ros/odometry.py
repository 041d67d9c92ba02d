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
The floating base's ground-truth odometry as the simulator bridge publishes it (nav_msgs/Odometry).

Pose in ``world``, twist in ``base_link`` (``child_frame_id``, as nav_msgs asks); a bridge told
not to publish the twist marks it unknown (``covariance[0] = -1``).
"""

from __future__ import annotations

from nav_msgs.msg import Odometry
import numpy as np

from ..math.rotations import quaternion_xyzw


def odometry(T: np.ndarray, twist: np.ndarray, stamp, with_twist: bool) -> Odometry:
    """Make the message of the base pose ``T`` (4x4, world) and ``twist`` (world axes, 6)."""
    R = T[:3, :3]
    m = Odometry()
    m.header.stamp = stamp
    m.header.frame_id = 'world'
    m.child_frame_id = 'base_link'
    p = m.pose.pose
    p.position.x, p.position.y, p.position.z = (float(v) for v in T[:3, 3])
    # (pin.Quaternion(R) leaks: see quaternion_xyzw)
    x, y, z, w = (float(c) for c in quaternion_xyzw(R))
    p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = x, y, z, w
    if not with_twist:
        m.twist.covariance[0] = -1.0
        return m
    lin, ang = R.T @ twist[:3], R.T @ twist[3:]
    t = m.twist.twist
    t.linear.x, t.linear.y, t.linear.z = (float(v) for v in lin)
    t.angular.x, t.angular.y, t.angular.z = (float(v) for v in ang)
    return m
