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
The bridge's pushes: an external force on a link of the simulated robot, from a topic.

``~/external_force`` (geometry_msgs/WrenchStamped): ``header.frame_id`` names a link of the
simulated robot, ``wrench.force`` is a force in the world frame [N] applied at that link frame's
origin at every simulation step until the next message replaces it; a zero force ends the push.
What a test or a user disturbs a controller with (a shove on the trunk, a tug on the hand),
timed in simulated time by when the messages arrive: in lockstep, a message taken before a
command acts from that command's first step.

Refused with a throttled line naming the cause, the push then in effect unchanged: an unknown
link, a force not finite or above ``max_external_force`` [N, 2000], a torque (not applied: a
force at the link's origin only, the same in both simulators).
"""

from __future__ import annotations

from geometry_msgs.msg import WrenchStamped
import numpy as np

from .common import DEFAULT_QOS, param


class SimPush:
    """
    The bridge's part that applies the external force ``~/external_force`` asks for.

    ``node``: the bridge (``param``, ``create_subscription``, ``say``, ``get_logger``); ``robot``:
    the simulated robot (``has_link``, ``apply_external_force``); ``now``: the simulated time.
    """

    def __init__(self, node, robot, now):
        self._node, self._robot, self._now = node, robot, now
        self.max_force = float(param(node, 'max_external_force', 2000.0))
        if not (np.isfinite(self.max_force) and self.max_force > 0.0):
            raise ValueError(f'max_external_force must be finite and > 0 N, got {self.max_force}')
        self.link: str | None = None
        self.force = np.zeros(3)
        node.create_subscription(WrenchStamped, '~/external_force', self._on_force, DEFAULT_QOS)

    def _on_force(self, msg: WrenchStamped) -> None:
        link = msg.header.frame_id
        f = msg.wrench.force
        force = np.array([f.x, f.y, f.z], dtype=float)
        t = msg.wrench.torque
        cause = None
        if not self._robot.has_link(link):
            cause = f"no link '{link}' in the simulated robot (header.frame_id names the link)"
        elif not np.isfinite(force).all():
            cause = f'force not finite: {force.tolist()}'
        elif np.linalg.norm(force) > self.max_force:
            cause = (f'{np.linalg.norm(force):.4g} N is above max_external_force '
                     f'({self.max_force:.4g} N)')
        elif any(v != 0.0 for v in (t.x, t.y, t.z)):
            cause = "a torque: only a force at the link frame's origin is applied"
        if cause is not None:
            self._node.say('warning', 'external_force', f'external force refused: {cause}; '
                           'the push in effect unchanged')
            return
        ending = not force.any()
        if (None if ending else link) == self.link and np.array_equal(force, self.force):
            return  # the push in effect, again (a stream): said when it began
        self._node.get_logger().info(
            f"external force on '{link}' ended at t = {self._now():.4f} s (simulated)"
            if ending else
            f"external force {np.round(force, 6).tolist()} N on '{link}' from "
            f't = {self._now():.4f} s (simulated)'
        )
        self.link, self.force = (None, np.zeros(3)) if ending else (link, force)

    def before_step(self) -> None:
        """Apply the push in effect during the next simulation step (the simulators forget it)."""
        if self.link is not None:
            self._robot.apply_external_force(self.link, self.force)

    def reset(self) -> None:
        """End any push (the robot put back at its start)."""
        self.link, self.force = None, np.zeros(3)
