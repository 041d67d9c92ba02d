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
``~/obstacles`` (visualization_msgs/MarkerArray): obstacles for the collision constraints.

A marker's identity is its ``ns`` and ``id``. ADD (or MODIFY, the same action) adds it or, when it
exists, moves it (republish to move an obstacle); DELETE removes it, DELETEALL removes them all.
Types: SPHERE (radius scale.x / 2), CUBE (scale x, y, z), CYLINDER (radius scale.x / 2, length
scale.z). ``header.frame_id``: ``world``, empty for the robot's base frame, or a link of the model
(the obstacle moves with it). A bad marker (another type, NaN, a scale not > 0, an unknown frame)
is refused with a throttled log line naming it and the cause; the other markers of the array, and
the controller, are unaffected. Nothing here when the configuration has no collision constraint.
"""

from __future__ import annotations

import numpy as np
from visualization_msgs.msg import Marker, MarkerArray

from .common import DEFAULT_QOS, pose_to_matrix, stamp_to_sec
from ..constraint.collision_avoidance import CollisionAvoidanceConstraint
from ..constraint.obstacle_velocity import ObstacleVelocity

_SHAPES = {Marker.SPHERE: 'sphere', Marker.CUBE: 'box', Marker.CYLINDER: 'cylinder'}


def marker_action(m, known) -> int:
    """
    Return the marker's action (ADD, DELETE or DELETEALL) for the obstacles ``known``.

    ValueError for another action, or a DELETE of an obstacle that does not exist.
    """
    if m.action == Marker.DELETE and f'{m.ns}/{m.id}' not in known:
        raise ValueError('DELETE of an obstacle that does not exist')
    if m.action not in (Marker.ADD, Marker.DELETE, Marker.DELETEALL):
        raise ValueError(f'action {m.action} is not ADD, DELETE or DELETEALL')
    return m.action


def marker_obstacle(m, base_frame: str):
    """Return (shape, size, pose 4x4, frame) of an ADD marker; ValueError naming what is wrong."""
    shape = _SHAPES.get(m.type)
    if shape is None:
        raise ValueError(f'type {m.type} is not SPHERE, CUBE or CYLINDER')
    s = np.array([m.scale.x, m.scale.y, m.scale.z], dtype=float)
    p, o = m.pose.position, m.pose.orientation
    values = np.array([p.x, p.y, p.z, o.x, o.y, o.z, o.w], dtype=float)
    if not (np.isfinite(s).all() and np.isfinite(values).all()):
        raise ValueError('NaN or infinite scale or pose')
    if not np.linalg.norm(values[3:]) > 1e-6:
        raise ValueError('zero orientation quaternion')
    size = {'sphere': [s[0] / 2.0], 'box': list(s), 'cylinder': [s[0] / 2.0, s[2]]}[shape]
    if min(size) <= 0.0:
        raise ValueError(f'scale {s.tolist()} not > 0')
    frame = m.header.frame_id
    frame = base_frame if frame == '' else (None if frame == 'world' else frame)
    return shape, size, pose_to_matrix(m.pose), frame


class ObstacleInput:
    """
    The collision constraints' obstacles from ``~/obstacles``: a part of the controller node.

    ``node`` subscribes (nothing without a collision constraint), logs (``say``) and gives the
    controller's time (``now()``); ``lockstep``: the node's cycles follow the simulated time the
    states carry (trigger ``joint_state``), and so does a stamped pose.
    """

    def __init__(self, node, controller, robot, lockstep: bool):
        self.node, self.robot, self.lockstep = node, robot, lockstep
        self.collision = [c for c in controller.get_constraints()
                          if isinstance(c, CollisionAvoidanceConstraint)]
        self.specs: dict = {}  # name -> (shape, size, frame) of the obstacles from markers
        self.velocities = ObstacleVelocity()  # of the obstacles, from their poses
        if self.collision:
            node.create_subscription(MarkerArray, '~/obstacles', self.on_obstacles, DEFAULT_QOS)

    def on_obstacles(self, msg: MarkerArray) -> None:
        """Apply each marker of ``msg``; a bad one is refused with a line naming it."""
        for m in msg.markers:
            name = f'{m.ns}/{m.id}'
            try:
                self.apply(m, name)
            except (ValueError, KeyError) as exc:
                self.node.say('warning', 'obstacles', f"obstacle marker '{name}' refused: {exc}")

    def apply(self, m, name: str) -> None:
        """Add, move or remove the obstacle of marker ``m`` in every collision constraint."""
        action = marker_action(m, self.specs)
        if action != Marker.ADD:
            for n in list(self.specs) if action == Marker.DELETEALL else [name]:
                for c in self.collision:
                    c.remove_obstacle(n)
                del self.specs[n]
                self.velocities.forget(n)
            return
        shape, size, pose, frame = marker_obstacle(m, self.robot.get_base_frame())
        spec = (shape, size, frame)
        # the instant of the pose: its stamp where it has one (a pose and its time travel
        # together), else its receipt; receipts jitter against the poses (in lockstep, a marker
        # computed for one step read in the next), and the velocity with them
        stamped = stamp_to_sec(m.header.stamp) > 0.0
        now = stamp_to_sec(m.header.stamp) if stamped else self.node.now()
        if self.specs.get(name) != spec or frame is not None:
            self.velocities.forget(name)  # a new shape, or one carried by a link
        # republished in the world: its velocity from its poses (the stamps' clock, or the
        # receipts': no velocity across the two)
        velocity = self.velocities.observe(name, pose[:3, 3], now, stamped)
        # the pose's time on the controller's clock: its stamp in lockstep (the simulated time
        # the states carry), its receipt otherwise; the constraint carries it on from there
        at = now if (stamped and self.lockstep) or not stamped else None
        for c in self.collision:
            if self.specs.get(name) == spec:
                c.move_obstacle(name, pose, frame, velocity, at)
            else:
                c.add_obstacle(name, shape, size, pose, frame)
        self.specs[name] = spec
