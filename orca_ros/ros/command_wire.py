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
The commands on the wire: one message type per ``command_message``, one layout per interface.

``float64_multi_array`` (default; :class:`ArrayWire`): std_msgs/Float64MultiArray. One field per
joint (``effort``, ``position``, ``velocity``): n values in the order of the ``joints``
parameter, as ros2_control's forward_command_controller takes them; the layout is empty, or one
dimension (lockstep: its label names the state the command answers, :data:`.common.ANSWERS`).
Several fields (``position_velocity``, ``joint_impedance``): field-major, data[i n + j] = field
i of joint j, with two dimensions: ``fields`` (label: the fields' names joined by commas, e.g.
``position,velocity,effort,stiffness,damping``; size k, stride k n) and ``joints`` (label
``joints``, or the answered state in lockstep; size n, stride n).

``joint_state`` (:class:`JointStateWire`): sensor_msgs/JointState by name, as topic-based
ros2_control hardware and Isaac Sim read commands: ``name`` the joints, ``position``,
``velocity``, ``effort`` filled for the interface's fields, the others empty. Gains are not
carried: in joint impedance the drive applies its own (configured alike on both sides). The
stamp is the answered state's in lockstep, the sender's clock otherwise.

A reader refuses a message whose size, fields or joint names are not those of its interface.
"""

from __future__ import annotations

import numpy as np
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from .common import answered_ns, ANSWERS, stamp_ns

#: the message types a command may go as
MESSAGES = ('float64_multi_array', 'joint_state')


def command_wire(message: str, fields, joints, lockstep: bool):
    """Return the wire of ``message`` for ``fields`` of ``joints``; ValueError naming a misfit."""
    if message == 'float64_multi_array':
        return ArrayWire(fields, joints, lockstep)
    if message == 'joint_state':
        return JointStateWire(fields, joints, lockstep)
    raise ValueError(f"command_message '{message}' is not one of {', '.join(MESSAGES)}")


class ArrayWire:
    """Commands as std_msgs/Float64MultiArray (see the module)."""

    message_type = Float64MultiArray

    def __init__(self, fields, joints, lockstep: bool):
        self.fields, self.n, self._lockstep = tuple(fields), len(joints), lockstep

    def message(self) -> Float64MultiArray:
        """Make an empty command message, with its layout."""
        msg = Float64MultiArray()
        k, n = len(self.fields), self.n
        msg.data = [0.0] * (k * n)
        joints = MultiArrayDimension(label='joints', size=n, stride=n)
        if k > 1:
            msg.layout.dim = [
                MultiArrayDimension(label=','.join(self.fields), size=k, stride=k * n), joints
            ]
        elif self._lockstep:
            msg.layout.dim = [joints]
        return msg

    def write(self, msg, values, clock) -> None:
        """Put ``values`` (fields x n, wire order) in ``msg`` (``clock``: unused here)."""
        msg.data = np.asarray(values, dtype=float).ravel().tolist()

    def set_answered(self, msg, answered_ns_: int) -> None:
        """Name the state (its stamp [ns]) a lockstep command answers, in its joints' dimension."""
        msg.layout.dim[-1].label = f'{ANSWERS}{answered_ns_}'

    @staticmethod
    def answered(msg) -> int | None:
        """Return the instant [ns] of the state ``msg`` answers, or None if it names none."""
        return answered_ns(msg)

    def read(self, msg) -> np.ndarray:
        """Return the command's values, fields x n (wire order); ValueError naming a misfit."""
        k, n, fields = len(self.fields), self.n, self.fields
        if len(msg.data) != k * n:
            per = f"{k} fields ({','.join(fields)}) of " if k > 1 else ''
            raise ValueError(f'{len(msg.data)} values for {per}{n} joints')
        if k > 1:
            dim = msg.layout.dim
            if not dim or dim[0].label != ','.join(fields):
                got = dim[0].label if dim else 'no layout'
                raise ValueError(f"fields '{got}', expected '{','.join(fields)}'")
        return np.asarray(msg.data, dtype=float).reshape(k, n)


class JointStateWire:
    """Commands as sensor_msgs/JointState by name (see the module)."""

    message_type = JointState
    CARRIED = ('position', 'velocity', 'effort')

    def __init__(self, fields, joints, lockstep: bool):
        self.fields, self.joints, self._lockstep = tuple(fields), list(joints), lockstep
        self.carried = tuple(f for f in self.fields if f in self.CARRIED)
        self._row = {f: k for k, f in enumerate(self.fields)}

    def message(self) -> JointState:
        """Make an empty command message naming the joints."""
        msg = JointState()
        msg.name = list(self.joints)
        return msg

    def write(self, msg, values, clock) -> None:
        """Put ``values`` (fields x n, wire order) in ``msg``; ``clock`` stamps free running."""
        for f in self.carried:
            setattr(msg, f, np.asarray(values[self._row[f]], dtype=float).tolist())
        if not self._lockstep:
            msg.header.stamp = clock.now().to_msg()

    def set_answered(self, msg, answered_ns_: int) -> None:
        """Stamp a lockstep command with the state it answers."""
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(answered_ns_), 10**9)

    @staticmethod
    def answered(msg) -> int | None:
        """Return the stamp [ns] of ``msg`` (the state it answers in lockstep), None if zero."""
        ns = stamp_ns(msg.header.stamp)
        return ns or None

    def read(self, msg) -> np.ndarray:
        """
        Return the carried fields' values, fields x n (wire order), by name.

        The fields it does not carry (the gains) are left NaN, for the reader to fill. ValueError
        naming a joint missing, or a field of the wrong size.
        """
        index = {name: i for i, name in enumerate(msg.name)}
        missing = [j for j in self.joints if j not in index]
        if missing:
            raise ValueError(f'no command for joints {missing}')
        take = [index[j] for j in self.joints]
        values = np.full((len(self.fields), len(self.joints)), np.nan)
        for f in self.carried:
            got = getattr(msg, f)
            if len(got) != len(msg.name):
                raise ValueError(f'{len(got)} {f} values for {len(msg.name)} names')
            values[self._row[f]] = np.asarray(got, dtype=float)[take]
        return values
