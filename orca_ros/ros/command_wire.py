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
The commands on the wire: std_msgs/Float64MultiArray, one layout per command interface.

One field per joint (``effort``, ``position``, ``velocity``): n values in the order of the
``joints`` parameter, as ros2_control's forward_command_controller takes them; the layout is
empty, or one dimension (lockstep: its label names the state the command answers,
:data:`.common.ANSWERS`). Several fields (``position_velocity``, ``joint_impedance``): field-major,
data[i n + j] = field i of joint j, with two dimensions: ``fields`` (label: the fields' names
joined by commas, e.g. ``position,velocity,effort,stiffness,damping``; size k, stride k n) and
``joints`` (label ``joints``, or the answered state in lockstep; size n, stride n). A reader
refuses a message whose size or field names are not those of its interface.
"""

from __future__ import annotations

import numpy as np
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

from .common import ANSWERS


def command_message(fields, n: int, lockstep: bool) -> Float64MultiArray:
    """Make an empty command message of ``fields`` for n joints, with its layout (see module)."""
    msg = Float64MultiArray()
    msg.data = [0.0] * (len(fields) * n)
    k = len(fields)
    joints = MultiArrayDimension(label='joints', size=n, stride=n)
    if k > 1:
        msg.layout.dim = [
            MultiArrayDimension(label=','.join(fields), size=k, stride=k * n), joints
        ]
    elif lockstep:
        msg.layout.dim = [joints]
    return msg


def set_answered(msg: Float64MultiArray, answered_ns: int) -> None:
    """Name the state (its stamp [ns]) a lockstep command answers, in its joints' dimension."""
    msg.layout.dim[-1].label = f'{ANSWERS}{answered_ns}'


def read_command(msg: Float64MultiArray, fields, n: int) -> np.ndarray:
    """Return the command's values, fields x n (wire order); ValueError naming a misfit."""
    k = len(fields)
    if len(msg.data) != k * n:
        per = f"{k} fields ({','.join(fields)}) of " if k > 1 else ''
        raise ValueError(f'{len(msg.data)} values for {per}{n} joints')
    if k > 1:
        dim = msg.layout.dim
        if not dim or dim[0].label != ','.join(fields):
            got = dim[0].label if dim else 'no layout'
            raise ValueError(f"fields '{got}', expected '{','.join(fields)}'")
    return np.asarray(msg.data, dtype=float).reshape(k, n)
