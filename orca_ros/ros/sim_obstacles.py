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
The bridge's obstacles: the controller's ``~/obstacles`` markers as bodies in PyBullet.

The same MarkerArray the controller reads (``obstacles_topic``, default
``/orca_controller/obstacles``; empty: none), the same conversion
(:func:`~orca_ros.ros.obstacle_markers.marker_obstacle`): each obstacle becomes a static body of
its shape, so that a collision in the simulation is a real one. ``world`` and the base frame
(empty ``frame_id``) are placed; a marker in a link's frame is refused here (the simulator would
have to weld it to the link) with a throttled log line, as bad markers are. So is an obstacle that
would go more than ``OVERLAP`` into the robot's moving links, added or moved (a marker of 100 m for
10 cm): PyBullet would push the links out of it at once, as no real obstacle can (the lwr's joints
at 100 rad/s); a moved one stays where it was.
"""

from __future__ import annotations

import numpy as np
import pybullet
from visualization_msgs.msg import Marker, MarkerArray

from .common import DEFAULT_QOS, param
from .obstacle_markers import marker_action, marker_obstacle
from ..math.rotations import quaternion_xyzw

#: the deepest an obstacle may go into the robot's moving links [m] (a foot on a ground box: 0)
OVERLAP = 0.01


class SimObstacles:
    def setup_obstacles(self) -> None:
        self._bodies: dict = {}  # marker name -> (PyBullet body, (shape, size))
        topic = str(param(self, 'obstacles_topic', '/orca_controller/obstacles'))
        if topic:
            self.create_subscription(MarkerArray, topic, self._on_obstacles, DEFAULT_QOS)

    def _on_obstacles(self, msg: MarkerArray) -> None:
        for m in msg.markers:
            name = f'{m.ns}/{m.id}'
            try:
                self._apply_marker(m, name)
            except ValueError as exc:
                self.say('warning', 'obstacles', f"obstacle marker '{name}' not simulated: {exc}")

    def _remove(self, name: str) -> None:
        body, _ = self._bodies.pop(name)
        self.server.client.removeBody(body)

    def _apply_marker(self, m, name: str) -> None:
        action = marker_action(m, self._bodies)
        if action != Marker.ADD:
            for n in list(self._bodies) if action == Marker.DELETEALL else [name]:
                self._remove(n)
                self.get_logger().info(f"obstacle '{n}' removed from the simulation")
            return
        shape, size, pose, frame = marker_obstacle(m, '')
        if frame not in (None, ''):
            raise ValueError(f"frame '{frame}': only world and the base frame are simulated")
        if frame == '':  # the base frame
            pose = self.model.get_world_to_base_transform() @ pose
        position, orientation = pose[:3, 3].tolist(), quaternion_xyzw(pose[:3, :3]).tolist()
        c = self.server.client
        known = self._bodies.get(name)
        if known is not None and known[1] == (shape, size):
            was = c.getBasePositionAndOrientation(known[0])
            c.resetBasePositionAndOrientation(known[0], position, orientation)
            try:
                self._check_overlap(known[0])
            except ValueError:
                c.resetBasePositionAndOrientation(known[0], *was)
                raise
            return
        if known is not None:
            self._remove(name)
        if shape == 'sphere':
            kw = {'shapeType': pybullet.GEOM_SPHERE, 'radius': size[0]}
        elif shape == 'box':
            kw = {'shapeType': pybullet.GEOM_BOX, 'halfExtents': (np.asarray(size) / 2).tolist()}
        else:
            kw = {'shapeType': pybullet.GEOM_CYLINDER, 'radius': size[0]}
        col = c.createCollisionShape(**kw, **({'height': size[1]} if shape == 'cylinder' else {}))
        vis = c.createVisualShape(**kw, **({'length': size[1]} if shape == 'cylinder' else {}),
                                  rgbaColor=[0.8, 0.3, 0.2, 0.6])
        body = c.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=col,
                                 baseVisualShapeIndex=vis, basePosition=position,
                                 baseOrientation=orientation)
        try:
            self._check_overlap(body)
        except ValueError:
            c.removeBody(body)
            raise
        self._bodies[name] = (body, (shape, size))
        self.get_logger().info(f"obstacle '{name}' in the simulation ({shape} {size})")

    def _check_overlap(self, body: int) -> None:
        """Raise ValueError if ``body`` goes more than OVERLAP into the robot's moving links."""
        c, robot = self.server.client, self.model
        deepest = None
        for p in c.getClosestPoints(bodyA=body, bodyB=robot.body, distance=0.0):
            if (p[4] >= 0 or not robot.fixed_base) and (deepest is None or p[8] < deepest[8]):
                deepest = p
        if deepest is not None and deepest[8] < -OVERLAP:
            link = (c.getJointInfo(robot.body, deepest[4])[12].decode() if deepest[4] >= 0
                    else 'base')
            raise ValueError(f'it would go {-deepest[8] * 1e3:.0f} mm into the robot '
                             f"('{link}'): no real obstacle can")
