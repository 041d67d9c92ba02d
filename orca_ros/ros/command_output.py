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
The controller node's command interface: effort commands out, the safe command, the hold at exit.

A part of :class:`.controller_node.OrcaControllerNode` (a mixin: the same node). Every command
goes out through :meth:`_publish` (model order in, ``joints`` order on the wire; in lockstep
naming the state it answers, :data:`.common.ANSWERS`); a fault sends the safe command with a
log line naming its cause once per spell; shutdown sends the hold and waits for its delivery.
"""

from __future__ import annotations

import time

import numpy as np
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from .common import ANSWERS, COMMAND_WRITER_QOS, param


class CommandOutput:
    """The effort command publication of the controller node (see the module)."""

    def _init_command_output(self) -> None:
        self._safe_reason = self._safe_cause = None
        self._safe_said = False  # the current safe spell's line is in the log
        self.commands_sent = 0  # every command published (solved, safe or hold)
        self._cmd_msg = Float64MultiArray()
        self._cmd_msg.data = [0.0] * self.n
        # lockstep: the command names the state it answers (common.ANSWERS)
        self._state_ns = 0
        self._cmd_dim = None
        if self.trigger == 'joint_state':
            self._cmd_dim = MultiArrayDimension(label=ANSWERS, size=self.n, stride=self.n)
            self._cmd_msg.layout.dim = [self._cmd_dim]
        self.pub_cmd = self.create_publisher(
            Float64MultiArray,
            str(param(self, 'command_topic', '/effort_controller/commands')),
            COMMAND_WRITER_QOS,
        )

    def _publish_safe(
        self, t: float, cause: str, reason: str, fresh: bool = True, level: str = 'warning'
    ) -> None:
        if reason != self._safe_reason:
            self._safe_reason, self._safe_cause, self._safe_said = reason, cause, False
        if not self._safe_said and self.say.due(cause):  # a line the throttle would hold back
            # (its cause said < 1 s ago) goes out once it may: no safe spell goes unnamed
            text = f'safe command: {reason}' if level != 'info' else f'holding: {reason}'
            self._safe_said = self.say(level, cause, text)
        cmd = self.safe.compute(
            t if fresh else time.monotonic(), self._last_cmd, self._q, self._v if fresh else None
        )
        self._publish(cmd)

    def _publish(self, cmd_model: np.ndarray) -> None:
        self._last_cmd[:] = cmd_model
        wire = np.empty(self.n)
        wire[self._wire_of_model] = cmd_model
        self._cmd_msg.data = wire.tolist()
        if self._cmd_dim is not None:
            self._cmd_dim.label = f'{ANSWERS}{self._state_ns}'
        self.pub_cmd.publish(self._cmd_msg)
        self.commands_sent += 1

    def shutdown_command(self) -> None:
        """
        On SIGINT / SIGTERM / shutdown, while the context is valid.

        Stop the loop and send the hold (gravity at the last state, zero when the drives compensate
        it), waiting until it is delivered.
        """
        self._stopped = True
        if not self._have_state:
            return
        self._publish(self.safe.hold(self._q, None))
        from rclpy.duration import Duration  # noqa: PLC0415

        delivered = self.pub_cmd.wait_for_all_acked(Duration(seconds=0.5))
        self.get_logger().info(
            'shutdown: hold command sent' + ('' if delivered else ' (delivery not confirmed)')
        )
