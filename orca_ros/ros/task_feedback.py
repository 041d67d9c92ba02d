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
The controller node's feedback: each task's pose and error, the cycles' timing, the markers.

A part of :class:`.controller_node.OrcaControllerNode`, published at ``feedback_rate`` in the
slack after a cycle's command (a :class:`.housekeeping.Housekeeping` job, one slice per task):
``~/tasks/<name>/current_pose`` (geometry_msgs/PoseStamped, base frame; Cartesian tasks),
``~/tasks/<name>/error`` (std_msgs/Float64MultiArray: pose error [linear, angular] or joint error),
``~/cycle_timing`` (Float64MultiArray: the cycles since the last message, as two rows of the
layout ``field`` x ``cycle``: controller time [s], then solve time [s]) and ``~/markers``
(:mod:`.controller_markers`). The Cartesian errors also feed the diagnostics' persistent-error
watch.
"""

from __future__ import annotations

from geometry_msgs.msg import PoseStamped
import numpy as np
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from .common import DEFAULT_QOS, matrix_to_pose
from ..task import CartesianTask, JointAccelerationTask


class TaskFeedback:
    """
    The node's feedback publishers (see the module).

    ``node``: where the publishers live, its time (``now()``) and whether the robot was seen
    (``have_state``); ``stats``: the loop's :class:`.loop_statistics.LoopStatistics`; ``watch``:
    the diagnostics' error watch; ``markers``: the :class:`.controller_markers.ControllerMarkers`.
    """

    def __init__(self, node, setup, robot, stats, watch, markers, rate: float, housekeeping):
        self.node, self.setup, self.robot = node, setup, robot
        self.stats, self.watch, self.markers = stats, watch, markers
        self._pubs = {}
        for name, task in setup.tasks.items():
            base = f'~/tasks/{name}'
            pose_pub = (node.create_publisher(PoseStamped, f'{base}/current_pose', DEFAULT_QOS)
                        if isinstance(task, CartesianTask) else None)
            err_pub = node.create_publisher(Float64MultiArray, f'{base}/error', DEFAULT_QOS)
            self._pubs[name] = (pose_pub, err_pub)
        self._timing_pub = node.create_publisher(Float64MultiArray, '~/cycle_timing', DEFAULT_QOS)
        self._timing_sent = 0
        if rate > 0:
            node.create_timer(1.0 / rate, housekeeping.timer_callback(self.publish))

    def publish(self):
        """Publish each task's pose and error, the cycles' timing and the markers (a job)."""
        if not self.node.have_state:
            return
        for name, task in self.setup.tasks.items():
            pose_pub, err_pub = self._pubs[name]
            err = Float64MultiArray()
            if isinstance(task, CartesianTask):
                servo = task.servo_controller()
                msg = PoseStamped()
                msg.header.stamp = self.node.get_clock().now().to_msg()
                msg.header.frame_id = self.robot.get_base_frame()
                matrix_to_pose(servo.get_current_cartesian_pose(), msg.pose)
                pose_pub.publish(msg)
                e = servo.get_cartesian_pose_error()
                self.watch.observe(
                    name, float(np.linalg.norm(e[:3])) if task.is_computing() else 0.0,
                    self.node.now(),
                )
                err.data = e.tolist()
            elif isinstance(task, JointAccelerationTask):
                err.data = task.get_position_error().tolist()
            err_pub.publish(err)
            yield
        self._publish_cycle_timing()
        yield
        self.markers.publish()

    def _publish_cycle_timing(self) -> None:
        total = self.stats.solve_times.total
        k = min(total - self._timing_sent, self.stats.solve_times.capacity)
        self._timing_sent = total
        if k <= 0:
            return
        msg = Float64MultiArray()
        msg.layout.dim = [
            MultiArrayDimension(label='field', size=2, stride=2 * k),
            MultiArrayDimension(label='cycle', size=k, stride=k),
        ]
        msg.data = np.concatenate(
            (self.stats.cycle_stamps.latest(k), self.stats.solve_times.latest(k))
        ).tolist()
        self._timing_pub.publish(msg)
