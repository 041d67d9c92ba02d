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
The controller node's command side: its command interface on the wire, the safe command, the hold.

A part of :class:`.controller_node.OrcaControllerNode` with a small interface: :meth:`solved` (a
solved cycle's torques and accelerations at the measured state), :meth:`hold` (a fault's,
with a log line naming its cause once per spell), :meth:`repeat` (the last command again, for a
state announced again in lockstep) and :meth:`shutdown_hold`. What goes out is the interface's
(:class:`orca_ros.command.JointCommand`: efforts, a position and/or velocity reference, or joint
impedance) as :mod:`.command_wire` lays it out (``command_message``: Float64MultiArray or
JointState), model order in, ``joints`` order on the wire; in lockstep each command names the
state it answers.
"""

from __future__ import annotations

import numpy as np

from .command_wire import command_wire
from .common import COMMAND_WRITER_QOS, param
from ..command import JointCommand


class CommandOutput:
    """The command publication of the controller node (see the module)."""

    def __init__(self, node, say, command, safe, wire_of_model, topic: str, lockstep: bool,
                 message: str = 'float64_multi_array', joints=None):
        self.say = say
        self.command = command  # orca_ros.command.JointCommand
        self.safe = safe  # orca_ros.safety.SafeCommand
        self.n = command.n
        self._wire_of_model = np.asarray(wire_of_model, dtype=int)
        self.reason = self.cause = None  # of the current safe spell
        self._said = False  # the current spell's line is in the log
        self.sent = 0  # every command published (solved, safe or hold)
        self.last_effort = np.zeros(self.n)  # model order: where a hold's fade starts
        self.answered = 0  # lockstep: the stamp [ns] of the state the next command answers
        self._lockstep = lockstep
        self.wire = command_wire(message, command.fields, joints or [''] * self.n, lockstep)
        self.msg = self.wire.message()
        self._wire = np.empty((len(command.fields), self.n))
        self._clock = node.get_clock()
        self.pub = node.create_publisher(self.wire.message_type, topic, COMMAND_WRITER_QOS)

    @classmethod
    def of_node(cls, node, robot, safe, wire_of_model, lockstep: bool, joints):
        """
        Make the node's command side from its parameters.

        ``command_interface``, ``joint_stiffness``, ``joint_damping``, the reference's leashes,
        ``command_topic``, ``command_message``; ValueError naming a bad one.
        """
        interface = str(param(node, 'command_interface', 'effort'))
        if bool(param(node, 'kinematic', False)) and interface in ('effort', 'joint_impedance'):
            raise ValueError(f'kinematic: no torques to send as {interface}: command_interface '
                             'must be position, velocity or position_velocity')
        command = JointCommand(
            interface,
            robot,
            param(node, 'joint_stiffness', []) or None,
            param(node, 'joint_damping', []) or None,
            float(param(node, 'reference_position_leash', 0.05)),
            float(param(node, 'reference_velocity_leash', 0.5)),
        )
        topic = str(param(node, 'command_topic', '/effort_controller/commands'))
        message = str(param(node, 'command_message', 'float64_multi_array'))
        return cls(node, node.say, command, safe, wire_of_model, topic, lockstep, message,
                   joints)

    def solved(self, q, v, tau, acceleration, dt: float) -> bool:
        """
        Send a solved cycle's command; False (nothing sent) when it is not finite.

        ``tau`` is clipped to the torque limits first.
        """
        if not (np.all(np.isfinite(tau)) and np.all(np.isfinite(acceleration))):
            return False  # the reference is left as it was
        tau = np.clip(tau, -self.safe.limit, self.safe.limit)
        values = self.command.solved(q, v, tau, acceleration, dt)
        self._send(values, tau if 'effort' not in self.command.fields
                   else self.command.field('effort'))
        return True

    def hold(self, t: float, cause: str, reason: str, q, v, fresh: bool = True,
             level: str = 'warning') -> None:
        """
        Send the hold of a fault (``reason``, logged once per spell under ``cause``).

        ``t``: the time the fade runs on; ``fresh`` False: (q, v) are not the robot's now (a stale
        state), the hold damps no velocity.
        """
        if reason != self.reason:
            self.reason, self.cause, self._said = reason, cause, False
        if not self._said and self.say.due(cause):  # a line the throttle would hold back
            # (its cause said < 1 s ago) goes out once it may: no safe spell goes unnamed
            text = f'safe command: {reason}' if level != 'info' else f'holding: {reason}'
            self._said = self.say(level, cause, text)
        hold = self.safe.compute(t, self.last_effort, q, v if fresh else None)
        self._send(self.command.held(q, hold), hold)

    def recovered(self) -> str | None:
        """End a safe spell; return its reason (None if there was none)."""
        reason = self.reason
        if reason is not None:
            self.reason = self.cause = None
            self.safe.reset()
        return reason

    def repeat(self) -> None:
        """Send the last command again (the answer to a state announced again), if any."""
        if self.sent:
            self.pub.publish(self.msg)

    def shutdown_hold(self, q) -> bool:
        """Send the hold at q (at rest, undamped) and wait for its delivery; True if confirmed."""
        from rclpy.duration import Duration  # noqa: PLC0415

        hold = self.safe.hold(q, None)
        self._send(self.command.held(q, hold), hold)
        return self.pub.wait_for_all_acked(Duration(seconds=0.5))

    def _send(self, values, effort) -> None:
        self.last_effort[:] = effort
        self._wire[:, self._wire_of_model] = values
        self.wire.write(self.msg, self._wire, self._clock)
        if self._lockstep:
            self.wire.set_answered(self.msg, self.answered)
        self.pub.publish(self.msg)
        self.sent += 1
