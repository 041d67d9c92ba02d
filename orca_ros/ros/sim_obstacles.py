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
The bridge's obstacles: the controller's ``~/obstacles`` markers as bodies in the simulation.

The same MarkerArray the controller reads (``obstacles_topic``, default
``/orca_controller/obstacles``; empty: none), the same conversion
(:func:`~orca_ros.ros.obstacle_markers.marker_obstacle`): each obstacle becomes a static body of
its shape in the world (``server.obstacles``: PyBullet's or MuJoCo's), so that a collision in the
simulation is a real one. ``world`` and the base frame (empty ``frame_id``) are placed; a marker
in a link's frame is refused here (the simulator would have to weld it to the link) with a
throttled log line, as bad markers are. So is an obstacle that would go more than ``OVERLAP``
into the robot's moving links, added or moved (a marker of 100 m for 10 cm): the simulator would
push the links out of it at once, as no real obstacle can (the lwr's joints flung far past
their velocity limits); a
moved one stays where it was.
"""

from __future__ import annotations

from visualization_msgs.msg import Marker, MarkerArray

from .common import DEFAULT_QOS, param
from .obstacle_markers import marker_action, marker_obstacle

#: the deepest an obstacle may go into the robot's moving links [m] (a foot on a ground box: 0)
OVERLAP = 0.01


class SimObstacles:
    """
    The bridge's part that keeps the simulation's obstacles as the markers say.

    ``node``: the bridge (its parameters, subscription and log: ``param``, ``create_subscription``,
    ``say``, ``get_logger``); ``world``: the simulated world (its ``obstacles``); ``robot``: the
    simulated robot (its base pose, its links for the overlap check).
    """

    def __init__(self, node, world, robot):
        self._node, self._world, self._robot = node, world, robot
        self._shapes: dict = {}  # marker name -> (shape, size) of the obstacle simulated
        topic = str(param(node, 'obstacles_topic', '/orca_controller/obstacles'))
        if topic:
            node.create_subscription(MarkerArray, topic, self._on_obstacles, DEFAULT_QOS)

    def _on_obstacles(self, msg: MarkerArray) -> None:
        for m in msg.markers:
            name = f'{m.ns}/{m.id}'
            try:
                self._apply_marker(m, name)
            except ValueError as exc:
                self._node.say('warning', 'obstacles',
                               f"obstacle marker '{name}' not simulated: {exc}")

    def _apply_marker(self, m, name: str) -> None:
        world = self._world.obstacles
        log = self._node.get_logger()
        action = marker_action(m, self._shapes)
        if action != Marker.ADD:
            for n in list(self._shapes) if action == Marker.DELETEALL else [name]:
                world.remove(n)
                del self._shapes[n]
                log.info(f"obstacle '{n}' removed from the simulation")
            return
        shape, size, pose, frame = marker_obstacle(m, '')
        if frame not in (None, ''):
            raise ValueError(f"frame '{frame}': only world and the base frame are simulated")
        if frame == '':  # the base frame
            pose = self._robot.get_world_to_base_transform() @ pose
        if self._shapes.get(name) == (shape, size):
            was = world.pose(name)
            world.move(name, pose)
            try:
                self._check_overlap(name)
            except ValueError:
                world.move(name, was)
                raise
            return
        if name in self._shapes:
            world.remove(name)
            del self._shapes[name]
        world.add(name, shape, size, pose)
        try:
            self._check_overlap(name)
        except ValueError:
            world.remove(name)
            raise
        self._shapes[name] = (shape, size)
        dims = ', '.join(f'{float(x):.4g}' for x in size)
        log.info(f"obstacle '{name}' in the simulation ({shape} [{dims}] m)")

    def _check_overlap(self, name: str) -> None:
        """Raise ValueError if obstacle ``name`` goes more than OVERLAP into the robot's links."""
        depth, link = self._world.obstacles.depth_into(name, self._robot)
        if depth > OVERLAP:
            raise ValueError(f"it would go {depth * 1e3:.0f} mm into the robot ('{link}'): "
                             'no real obstacle can')
