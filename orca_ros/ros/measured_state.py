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
The controller node's measured state: joint states and odometry in, the robot model's state out.

A part of :class:`.controller_node.OrcaControllerNode`. Joint states are read by name
(:class:`~orca_ros.ros.joint_state_input.JointStateInput`: the commanded and the locked joints;
NaN, absurd values and missing joints rejected with :class:`StateRejected`, naming the cause). A
floating base also needs odometry: the pose and the child-frame twist, checked and turned into
world axes. A twist marked unknown (covariance[0] = -1, as sensor_msgs has it) or ``odom_twist:
estimated``: the twist is estimated from the poses
(:class:`~orca_ros.robot.base_twist_estimator.BaseTwistEstimator`), said once in the log.

The part keeps the last accepted state and its stamps; what to do with a state (compute a cycle,
answer a lockstep simulator again) is the node's decision: :meth:`MeasuredState.read_joint_state`
says whether the state is of a new instant.
"""

from __future__ import annotations

import time

import numpy as np

from .common import pose_to_matrix, stamp_to_sec
from .joint_state_input import JointStateInput, StateRejected
from ..robot.base_twist_estimator import BaseTwistEstimator

__all__ = ['MeasuredState', 'StateRejected']

_TWIST_MODES = ('auto', 'measured', 'estimated')


class MeasuredState:
    """
    The last accepted joint state (and base odometry) and its stamps; sets it on the model.

    ``q``, ``v``: positions and velocities of the commanded joints in model order (read-only for
    other parts); ``stamp``: the joint state's stamp [s] (None before the first); ``wall``,
    ``odom_wall``: monotonic receipt times of the last valid joint state and odometry. ``lockstep``
    (the node's ``trigger: joint_state``): a state stamped at or before the last accepted one is a
    repetition (the simulator re-announcing an instant), not a new state.
    """

    def __init__(self, robot, joints, model_index, *, floating: bool, lockstep: bool,
                 position_margin: float, velocity_factor: float, odom_twist: str,
                 gravity, say):
        if odom_twist not in _TWIST_MODES:
            raise ValueError(
                f"odom_twist must be 'auto', 'measured' or 'estimated', got '{odom_twist}'"
            )
        self.robot = robot
        self.floating = floating
        self.lockstep = lockstep
        self.say = say
        self.joints, self.model_index = list(joints), model_index
        self.joint_input = JointStateInput(robot, joints, model_index, position_margin,
                                           velocity_factor)
        self.velocity_factor = velocity_factor
        n = len(self.joints)
        self.q, self.v = np.zeros(n), np.zeros(n)
        self._q_in, self._v_in = np.zeros(n), np.zeros(n)
        self.locked = robot.get_locked_joint_names()
        self._locked_q = np.zeros(len(self.locked))
        self.stamp = None
        self.wall = None
        self.base_T = np.eye(4)
        self.base_twist = np.zeros(6)
        self.odom_stamp = None
        self.odom_wall = None
        self.gravity = np.array(gravity, dtype=float)
        self.odom_twist = odom_twist
        self._twist_estimator = BaseTwistEstimator()
        self._estimating = False
        self._estimating_twist = False

    @property
    def ready(self) -> bool:
        """Say whether a joint state (and odometry for a floating base) was accepted."""
        return self.stamp is not None and (not self.floating or self.odom_stamp is not None)

    @property
    def instant_complete(self) -> bool:
        """Say whether joint state and odometry (floating base) are of the same instant."""
        return not self.floating or self.odom_stamp == self.stamp

    def set_plausibility(self, position_margin: float, velocity_factor: float) -> None:
        """Check the next joint states against new bounds; the velocity estimate goes on."""
        new_input = JointStateInput(self.robot, self.joints, self.model_index, position_margin,
                                    velocity_factor)
        new_input.estimator = self.joint_input.estimator
        self.joint_input = new_input
        self.velocity_factor = velocity_factor

    def read_joint_state(self, msg) -> bool:
        """
        Read a ``sensor_msgs/JointState``; return whether it is of a new instant.

        Raises :class:`StateRejected` (nothing kept) when a value is missing or implausible. A
        repetition (lockstep, stamped at or before the last) refreshes ``wall`` only.
        """
        stamp = stamp_to_sec(msg.header.stamp)
        self.joint_input.read(msg.name, msg.position, msg.velocity, self._q_in, self._v_in, stamp)
        estimating = self.joint_input.estimating
        if estimating != self._estimating:  # said once per spell
            self._estimating = estimating
            if estimating:
                self.say('warning', 'state:no_velocity', 'joint_states carry no velocities: '
                         'estimating them from the positions (filtered differences, 100 Hz)')
        self.wall = time.monotonic()
        if self.lockstep and self.stamp is not None and stamp <= self.stamp:
            return False
        self.q[:] = self._q_in
        self.v[:] = self._v_in
        self._locked_q[:] = self.joint_input.locked_positions
        self.stamp = stamp
        return True

    def read_odom(self, msg) -> bool:
        """Read a ``nav_msgs/Odometry`` (twist in ``child_frame_id``); return whether accepted."""
        p, o, tw = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist
        vals = np.array([p.x, p.y, p.z, o.x, o.y, o.z, o.w, tw.linear.x, tw.linear.y,
                         tw.linear.z, tw.angular.x, tw.angular.y, tw.angular.z], dtype=float)
        estimate = self.odom_twist == 'estimated' or (
            self.odom_twist == 'auto' and msg.twist.covariance[0] == -1.0
        )
        checked = vals[:7] if estimate else vals  # an unknown twist may hold anything
        if (not np.isfinite(checked).all() or np.abs(checked).max() > 1e6
                or not 0.5 < np.abs(vals[3:7]).sum() < 2.5):
            self.say(
                'error', 'odom', 'odom rejected: NaN, absurd (> 1e6) or non-unit-quaternion values'
            )
            return False
        T = pose_to_matrix(msg.pose.pose)
        R = T[:3, :3]
        self.base_T[:] = T
        if estimate:  # from the poses, over the messages' stamps (receipt time when unstamped)
            t = stamp_to_sec(msg.header.stamp)
            t = t if t > 0.0 else time.monotonic()
            self.base_twist[:] = self._twist_estimator.update(T, t)
        else:
            self.base_twist[:3] = R @ vals[7:10]  # child frame -> world axes
            self.base_twist[3:] = R @ vals[10:13]
        if estimate != self._estimating_twist:  # said once per spell
            self._estimating_twist = estimate
            if estimate:
                why = ('odom_twist: estimated' if self.odom_twist == 'estimated'
                       else 'odom twist unknown (covariance[0] = -1)')
                self.say('warning', 'state:no_twist', f'{why}: estimating the base twist from '
                         'the poses (filtered differences, 100 Hz)')
        self.odom_stamp = stamp_to_sec(msg.header.stamp)
        self.odom_wall = time.monotonic()
        return True

    def apply(self, q=None, v=None) -> None:
        """Set the measured state on the model; (q, v): other joint states (a control cycle's)."""
        q = self.q if q is None else q
        v = self.v if v is None else v
        if self.locked:
            self.robot.set_locked_joint_positions(self._locked_q)  # re-welds when they moved
        if self.floating:
            self.robot.set_robot_state(self.base_T, q, self.base_twist, v, self.gravity)
        else:
            self.robot.set_robot_state(q, v)
