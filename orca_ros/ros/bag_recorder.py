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
bag_recorder: a run written to a rosbag2 file (MCAP storage).

``ros2 bag``, Foxglove and PlotJuggler open it. Subscribes to ``topics`` (each ``'<topic>
<package>/msg/<Type>'``) without deserializing (raw CDR, as ``ros2 bag record`` stores it) and
writes with the ``rosbags`` library, so it runs wherever rclpy does, with or without the rosbag2
packages. Time stamps are the node's clock: simulated time with ``use_sim_time`` (lockstep runs:
the bridge publishes ``/clock``), else wall time. The bag is closed on SIGINT / SIGTERM.
``/robot_description`` is recorded with its transient-local QoS, so the plot command finds the
robot (and its limits) in the bag itself.

Receipts: on each topic of ``confirm_topics`` (default: the end effector's target), each distinct
message is logged once as ``recorded <topic> message <crc32 of its fields, 8 hex digits>`` (see
:func:`receipt`). A sender that must have its message in the bag (the main job's targets: a
publisher that nothing else waits for may not be matched with the recorder yet when it first
sends) repeats it until that line is in the recorder's log.
"""

from __future__ import annotations

import importlib
import os
import sys
import zlib

from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message

from .common import DESCRIPTION_QOS, param, run_node
from .guarded_node import GuardedNode
from ..utils.optional_import import optional_import

DEFAULT_TOPICS = [
    '/robot_description std_msgs/msg/String',
    '/joint_states sensor_msgs/msg/JointState',
    '/effort_controller/commands std_msgs/msg/Float64MultiArray',
    '/orca_controller/tasks/ee/target_pose geometry_msgs/msg/PoseStamped',
    '/orca_controller/tasks/ee/error std_msgs/msg/Float64MultiArray',
    '/orca_controller/cycle_timing std_msgs/msg/Float64MultiArray',
    '/diagnostics diagnostic_msgs/msg/DiagnosticArray',
]
DEFAULT_CONFIRM_TOPICS = ['/orca_controller/tasks/ee/target_pose']
# deep queues: a recorder that falls behind for a moment must not drop the 1 kHz streams
_BEST_EFFORT = QoSProfile(depth=5000, reliability=ReliabilityPolicy.BEST_EFFORT)
_RELIABLE = QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE)


def receipt(topic: str, msg) -> str:
    """
    Return the log line the recorder writes for a message (an rclpy message) on ``topic``.

    Of the message's fields (their repr: floats exactly), not of its CDR bytes: those hold
    alignment padding that the serializer leaves as it finds it (rclpy's serialize_message gave
    bytes of garbage where the wire had zeros), and a sender's receipt must not depend on it.
    """
    return f'recorded {topic} message {zlib.crc32(repr(msg).encode()):08x}'


def _message_class(type_name: str):
    pkg, kind, name = type_name.split('/')
    return getattr(importlib.import_module(f'{pkg}.{kind}'), name)


class BagRecorder(GuardedNode):
    def __init__(self, **kwargs):
        super().__init__('bag_recorder', **kwargs)
        rosbag2 = optional_import('rosbags.rosbag2', 'recording a run')
        typesys = optional_import('rosbags.typesys', 'recording a run')
        output = str(param(self, 'output', 'orca_run'))
        topics = list(param(self, 'topics', DEFAULT_TOPICS) or DEFAULT_TOPICS)
        best_effort = set(param(self, 'best_effort_topics', ['/joint_states', '/odom']) or [])
        confirm = set(param(self, 'confirm_topics', DEFAULT_CONFIRM_TOPICS) or [])
        self._receipts: dict[str, set] = {t: set() for t in confirm}
        self._classes: dict[str, type] = {}
        if os.path.exists(output):
            raise ValueError(f"'{output}' exists: a bag is never overwritten")
        typestore = typesys.get_typestore(typesys.Stores.ROS2_JAZZY)
        self.writer = rosbag2.Writer(
            output, version=8, storage_plugin=rosbag2.StoragePlugin.MCAP
        )
        self.writer.open()
        self.output = output
        self.counts: dict[str, int] = {}
        for entry in topics:
            try:
                topic, type_name = entry.split()
                cls = _message_class(type_name)
            except (ValueError, ImportError, AttributeError) as exc:
                raise ValueError(
                    f"topics entry '{entry}': expected '<topic> <package>/msg/<Type>' ({exc})"
                ) from None
            conn = self.writer.add_connection(topic, type_name, typestore=typestore)
            qos = (
                DESCRIPTION_QOS
                if topic.endswith('robot_description')
                else (_BEST_EFFORT if topic in best_effort else _RELIABLE)
            )
            self.counts[topic] = 0
            self._classes[topic] = cls
            self.create_subscription(
                cls, topic, lambda data, c=conn, t=topic: self._write(c, t, data), qos, raw=True
            )
        self.get_logger().info(f'recording {len(topics)} topics to {output} (MCAP)')

    def _write(self, conn, topic: str, data: bytes) -> None:
        self.writer.write(conn, self.get_clock().now().nanoseconds, data)
        self.counts[topic] += 1
        if self.counts[topic] == 1:  # a launcher may wait for this before starting the robot
            self.get_logger().info(f'first message on {topic}')
        seen = self._receipts.get(topic)
        if seen is not None:
            line = receipt(topic, deserialize_message(bytes(data), self._classes[topic]))
            if line not in seen:  # a sender waits for this to know the bag has its message
                seen.add(line)
                self.get_logger().info(line)

    def destroy_node(self):
        self.writer.close()
        self.get_logger().info(
            f'bag {self.output} closed: '
            + ', '.join(f'{t} {n}' for t, n in self.counts.items())
        )
        super().destroy_node()


def main(args=None) -> int:
    return run_node(BagRecorder, args, on_shutdown=None)


if __name__ == '__main__':
    sys.exit(main())
