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
Robots described in MJCF (MuJoCo's format), read by Pinocchio's parser.

The MuJoCo Menagerie's robots exist only as MJCF. Pinocchio makes each body a frame (its name)
and each hinge or slide joint a joint; ``range`` gives the position limits, ``actuatorfrcrange``
the torque limits; MJCF has no velocity limits (infinite). The floating base: a ``freejoint`` on
the root body, or one added at load (``floating_base``). What the parser refuses (an element it
does not know, a file it cannot read) is a ValueError naming it.
"""

from __future__ import annotations

import re

import pinocchio as pin

_ROOT = re.compile(r'^\s*(?:<\?xml[^>]*\?>\s*)?(?:<!--.*?-->\s*)*<(\w+)', re.S)


def is_mjcf(text: str) -> bool:
    """Tell MJCF text (root element ``<mujoco>``) from URDF (``<robot>``)."""
    m = _ROOT.match(text)
    return bool(m) and m.group(1) == 'mujoco'


def build_mjcf_model(path: str, floating_base: bool) -> pin.Model:
    """
    Return Pinocchio's model of the MJCF file ``path``, with a free-flyer root if floating.

    ValueError when the parser refuses the file (its message names the element), when the file's
    root body has a free joint and ``floating_base`` is False (a robot cannot be both), or when
    a free joint is not on the root (not a base).
    """
    try:
        model = pin.buildModelFromMJCF(path)
    except Exception as exc:  # Pinocchio raises ValueError/RuntimeError with its own text
        raise ValueError(f"could not parse MJCF '{path}': {exc}") from exc
    free = [j for j in range(1, model.njoints) if model.joints[j].shortname() ==
            'JointModelFreeFlyer']
    if free and free != [1]:
        raise ValueError(f"MJCF '{path}': free joint '{model.names[free[-1]]}' is not on the "
                         'root body: only a floating base may be free')
    if free and not floating_base:
        raise ValueError(f"MJCF '{path}': its root body has a free joint "
                         f"('{model.names[1]}'): load it with floating_base true")
    if floating_base and not free:
        model = pin.buildModelFromMJCFAndRootJoint(path, pin.JointModelFreeFlyer(), 'root_joint')
    return model
