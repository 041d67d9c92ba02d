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
The controller node's ``~/markers`` (visualization_msgs/MarkerArray), a part of the node.

At the feedback rate, for a robot with contacts (or a floating base): the centre of mass (ns
``com``: a SPHERE), the support polygon (ns ``support_polygon``: a closed LINE_STRIP at the
contacts' height; DELETE when fewer than three points support) and per computing contact an
ARROW from its point along the force of the last solution (ns ``contact_forces``, id = the
contact's index; its length is the force times ``marker_force_scale`` [m/N, 0.002]; DELETE while
the contact is off). Frame: the world; stamp: the state the model holds (in lockstep the
simulated instant of the last cycle). RViz shows them as they are; ``web_view`` draws them too.
Parameters: ``markers`` (true), ``marker_force_scale``.
"""

from __future__ import annotations

from geometry_msgs.msg import Point
from visualization_msgs.msg import Marker, MarkerArray

from .common import DEFAULT_QOS, param
from ..constraint.support_summary import support_summary

WORLD = 'world'
COM_COLOR = (1.0, 0.85, 0.0, 1.0)
POLYGON_COLOR = (0.1, 0.7, 0.2, 1.0)
FORCE_COLOR = (0.9, 0.2, 0.1, 1.0)


def _marker(ns: str, mid: int, kind: int, stamp, color, action=Marker.ADD) -> Marker:
    m = Marker(ns=ns, id=mid, type=kind, action=action)
    m.header.frame_id = WORLD
    m.header.stamp = stamp
    m.pose.orientation.w = 1.0
    m.color.r, m.color.g, m.color.b, m.color.a = color
    return m


def _point(p) -> Point:
    return Point(x=float(p[0]), y=float(p[1]), z=float(p[2]))


class ControllerMarkers:
    """
    The controller node's ``~/markers``: a part of the node (see the module).

    ``node`` declares the parameters and makes the publisher; ``stamp()`` gives the markers'
    stamp (the state the model holds); ``contacts``: the layout's, in wrench order.
    """

    def __init__(self, node, robot, contacts, floating: bool, stamp):
        self.robot, self.stamp = robot, stamp
        self.contacts = list(contacts)
        self.force_scale = float(param(node, 'marker_force_scale', 0.002))
        self.publisher = None
        if bool(param(node, 'markers', True)) and (self.contacts or floating):
            self.publisher = node.create_publisher(MarkerArray, '~/markers', DEFAULT_QOS)

    def publish(self) -> None:
        """
        Send the markers of the model's current state and the last solution, when heard.

        Nobody subscribed, none is built: a MarkerArray of the quadruped costs about as much CPU
        as a control cycle, and a 1 kHz node has no cycle to spare for markers nobody draws.
        Call it once the model holds a state.
        """
        if self.publisher is None or self.publisher.get_subscription_count() == 0:
            return
        s = support_summary(self.robot, self.contacts)
        stamp = self.stamp()
        com = _marker('com', 0, Marker.SPHERE, stamp, COM_COLOR)
        com.pose.position = _point(s.com)
        com.scale.x = com.scale.y = com.scale.z = 0.04
        ok = len(s.polygon) >= 3
        poly = _marker('support_polygon', 0, Marker.LINE_STRIP, stamp, POLYGON_COLOR,
                       Marker.ADD if ok else Marker.DELETE)
        if ok:
            poly.points = [_point(p) for p in list(s.polygon) + [s.polygon[0]]]
            poly.scale.x = 0.006  # line width
        markers = [com, poly]
        forces = {f.name: f for f in s.contacts}
        for k, c in enumerate(self.contacts):
            f = forces.get(c.name)
            arrow = _marker('contact_forces', k, Marker.ARROW, stamp, FORCE_COLOR,
                            Marker.ADD if f is not None else Marker.DELETE)
            if f is not None:
                arrow.points = [_point(f.point), _point(f.point + self.force_scale * f.force)]
                arrow.scale.x, arrow.scale.y, arrow.scale.z = 0.01, 0.02, 0.02
                arrow.text = c.name
            markers.append(arrow)
        self.publisher.publish(MarkerArray(markers=markers))
