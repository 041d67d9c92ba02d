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
"""The recorder's receipts name a message by its fields, not by its CDR bytes."""

import pytest

pytest.importorskip('rclpy')

from geometry_msgs.msg import PoseStamped  # noqa: E402,I100
from orca_ros.ros.bag_recorder import receipt  # noqa: E402
from rclpy.serialization import deserialize_message, serialize_message  # noqa: E402


def test_a_receipt_does_not_depend_on_the_padding_bytes():
    """
    A PoseStamped with an empty frame id has 3 bytes of padding before its doubles.

    rclpy's serializer left them as it found them (seen: 70 85 02) where the DDS wire had zeros:
    a receipt of the CDR bytes then differed from the sender's, intermittently, and the main job
    waited for ever for a target the bag held (the two-host test, 1 run in 3 under load).
    """
    msg = PoseStamped()
    msg.pose.position.x = -0.5366844980679282
    msg.pose.orientation.w = 1.0
    # encapsulation (4 bytes), stamp (8), the string's length (4) and its NUL (1), the padding
    cdr = bytearray(serialize_message(msg))
    assert cdr[12:17] == b'\x01\x00\x00\x00\x00'
    lines = set()
    for pad in (b'\x00\x00\x00', b'\x70\x85\x02', b'\xff\xff\xff'):
        cdr[17:20] = pad
        lines.add(receipt('/t', deserialize_message(bytes(cdr), PoseStamped)))
    assert lines == {receipt('/t', msg)}
    # and a change of a field is a different message
    msg.pose.position.x += 1e-15
    assert receipt('/t', msg) not in lines
