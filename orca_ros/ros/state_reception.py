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
The controller node's state input: joint states and odometry in, the robot model's state out.

Joint states are read by name (:class:`~orca_ros.ros.joint_state_input.JointStateInput`: the
commanded and the locked joints, NaN, absurd values and missing joints rejected with a log line);
a floating base also needs odometry (pose and child-frame twist, checked and turned into world
axes). A twist marked unknown (covariance[0] = -1, as sensor_msgs has it) or ``odom_twist:
estimated``: the twist is estimated from the poses
(:class:`~orca_ros.robot.base_twist_estimator.BaseTwistEstimator`), said once in the log. In
lockstep (``trigger: joint_state``) a state repeated with the same stamp re-sends the command of
that instant instead of computing another step; a new instant computes once both joint
states and odometry of it are in.
"""

from __future__ import annotations

import time

from nav_msgs.msg import Odometry
import numpy as np
from sensor_msgs.msg import JointState

from .common import pose_to_matrix, stamp_ns, stamp_to_sec
from .joint_state_input import StateRejected


class StateReception:
    def _on_joint_state(self, msg: JointState) -> None:
        stamp = stamp_to_sec(msg.header.stamp)
        try:
            self.joint_input.read(msg.name, msg.position, msg.velocity, self._q_in, self._v_in,
                                  stamp)
        except StateRejected as exc:
            self.say('error', exc.cause, str(exc))
            if (self.trigger == 'joint_state' and self.have_state and not self._stopped
                    and stamp > self._state_stamp):
                # lockstep: the simulator steps only once the state of a new instant is answered;
                # the hold answers (without it the loop stopped for good: a joint speeding past
                # the plausible, its state rejected, no command, the same state announced again).
                # Others' (unstamped, older) are only told: the simulator does not wait on them
                self.output.answered = stamp_ns(msg.header.stamp)
                self._publish_safe(self.now(), 'safe:state', f'joint state rejected ({exc})',
                                   fresh=False)
            return
        estimating = self.joint_input.estimating
        if estimating != getattr(self, '_estimating', False):  # said once per spell
            self._estimating = estimating
            if estimating:
                self.say('warning', 'state:no_velocity', 'joint_states carry no velocities: '
                         'estimating them from the positions (filtered differences, 100 Hz)')
        if (
            self.trigger == 'joint_state'
            and self._state_stamp is not None
            and stamp <= self._state_stamp
        ):
            self.state_wall = time.monotonic()
            # a repeated state: the simulator re-announces itself when no command reached it (e.g.
            # sent before discovery matched it). Computing again would add a step; the command of
            # that instant is sent again
            if self._stopped:
                return
            if stamp == self._computed_stamp:
                self.output.repeat()
            elif stamp == self._state_stamp:  # not answered yet (the cycle that froze the
                # collector sends nothing): answered now
                self._on_new_state()
            return
        self._q[:] = self._q_in
        self._v[:] = self._v_in
        self._locked_q[:] = self.joint_input.locked_positions
        self.state_wall = time.monotonic()
        self._state_stamp = stamp
        self.output.answered = stamp_ns(msg.header.stamp)
        self._on_new_state()

    def _on_odom(self, msg: Odometry) -> None:
        p, o = msg.pose.pose.position, msg.pose.pose.orientation
        tw = msg.twist.twist
        vals = np.array(
            [
                p.x,
                p.y,
                p.z,
                o.x,
                o.y,
                o.z,
                o.w,
                tw.linear.x,
                tw.linear.y,
                tw.linear.z,
                tw.angular.x,
                tw.angular.y,
                tw.angular.z,
            ],
            dtype=float,
        )
        estimate = self._odom_twist == 'estimated' or (
            self._odom_twist == 'auto' and msg.twist.covariance[0] == -1.0
        )
        checked = vals[:7] if estimate else vals  # an unknown twist may hold anything
        if (
            not np.isfinite(checked).all()
            or np.abs(checked).max() > 1e6
            or not 0.5 < np.abs(vals[3:7]).sum() < 2.5
        ):
            self.say(
                'error', 'odom', 'odom rejected: NaN, absurd (> 1e6) or non-unit-quaternion values'
            )
            return
        T = pose_to_matrix(msg.pose.pose)
        R = T[:3, :3]
        self._base_T[:] = T
        if estimate:  # from the poses, over the messages' stamps (receipt time when unstamped)
            t = stamp_to_sec(msg.header.stamp)
            t = t if t > 0.0 else time.monotonic()
            self._base_twist[:] = self._twist_estimator.update(T, t)
        else:
            self._base_twist[:3] = R @ vals[7:10]  # child frame -> world axes
            self._base_twist[3:] = R @ vals[10:13]
        if estimate != getattr(self, '_estimating_twist', False):  # said once per spell
            self._estimating_twist = estimate
            if estimate:
                why = ('odom_twist: estimated' if self._odom_twist == 'estimated'
                       else 'odom twist unknown (covariance[0] = -1)')
                self.say('warning', 'state:no_twist', f'{why}: estimating the base twist from '
                         'the poses (filtered differences, 100 Hz)')
        self._odom_stamp = stamp_to_sec(msg.header.stamp)
        self._odom_wall = time.monotonic()
        self._on_new_state()

    def _state_ready(self) -> bool:
        if self._state_stamp is None:
            return False
        return not self.floating or self._odom_stamp is not None

    def apply_state(self, q=None, v=None) -> None:
        """Set the measured state on the model; (q, v): other joint states (a control cycle's)."""
        q = self._q if q is None else q
        v = self._v if v is None else v
        if self._locked:
            self.robot.set_locked_joint_positions(self._locked_q)  # re-welds when they moved
        if self.floating:
            self.robot.set_robot_state(self._base_T, q, self._base_twist, v, self._gravity)
        else:
            self.robot.set_robot_state(q, v)

    def _on_new_state(self) -> None:
        if not self._state_ready():
            return
        if not self.have_state:
            self.have_state = True
            self.apply_state()
            self.get_logger().info('first joint state received: control starts')
            # far targets along trajectories, not as steps
            self.targets.start_configured(self.now(), self._q, self._v)
        if self.trigger == 'joint_state':
            # lockstep: one step per simulated instant, once joint state (and odom) of that instant
            # are in
            if self.floating and self._odom_stamp != self._state_stamp:
                return
            if self._computed_stamp == self._state_stamp:
                return
            self._computed_stamp = self._state_stamp
            self._control_step()
