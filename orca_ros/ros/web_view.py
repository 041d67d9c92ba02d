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
``web_view``: a live 3-D view of the robot and its Cartesian targets in the browser (viser).

The robot comes from ``robot_description`` (the latched topic; or the ``urdf_path`` parameter),
moved by ``joint_states`` (and ``odom`` with ``floating_base: true``). For every Cartesian task
of the controller (found by its ``<controller>/tasks/<name>/current_pose`` topic, so tasks of a
restarted or reconfigured controller appear by themselves) the page shows the current pose (a
magenta ball with axes) and the target as a gizmo: dragging it publishes
``<controller>/tasks/<name>/target_pose`` in the frame the controller reports the task in, so the
controller's own checks (frames, reach, smoothing) apply to it as to any other sender; a target
sent by anyone else moves the gizmo. The page's panel has, per task, an ``active`` checkbox
(calls the task's ``set_active``; shows the ``active_tasks`` of the controller's diagnostics) and
its error (``~/tasks/<name>/error``, position and orientation), and a live plot of the solve times
the controller's diagnostics report (median and 99th percentile, :mod:`..view.solve_times`).
The obstacles sent to the controller's ``~/obstacles`` (visualization_msgs/MarkerArray: SPHERE,
CUBE, CYLINDER in the world, the base frame or on a link; read as the controller reads them,
:mod:`.obstacle_markers`) are shown as blue shapes, each on a gizmo: dragging it sends the marker
moved (in its own frame) to ``~/obstacles``, where the controller reads it as any other. The
controller's ``~/markers`` (robots with contacts: the CoM, the support polygon, the contact forces
as arrows, :mod:`.controller_markers`; SPHERE, LINE_STRIP and ARROW markers in their colours) are
drawn as they come.

Parameters: ``host`` (127.0.0.1), ``port`` (8080; the next free one when taken), ``controller``
(``/orca_controller``), ``rate`` (30 Hz, scene updates), ``floating_base`` (false),
``gizmo_scale`` (0.2 m), ``plot_window`` (30 s of solve times), ``camera_position`` /
``camera_look_at`` / ``camera_fov`` (a tab's first view: [1.4, -1.4, 1.1], [0, 0, 0.4], 50
degrees), ``urdf_path`` (empty: the topic).
"""

from __future__ import annotations

import copy
import re
import sys
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import SetBool
from visualization_msgs.msg import Marker, MarkerArray

from .common import DEFAULT_QOS, DESCRIPTION_QOS, matrix_to_pose, param, pose_to_matrix, run_node
from .guarded_node import GuardedNode
from .obstacle_markers import marker_action, marker_obstacle
from ..utils.optional_import import MissingDependency, optional_import
from ..view.gizmos import GizmoBook
from ..view.solve_times import SolveTimeHistory

POSE_TYPE = 'geometry_msgs/msg/PoseStamped'
ERROR_PERIOD = 0.2  # s between two updates of a task's error on the page
# after a click the checkbox keeps the clicked value until the controller's diagnostics agree
# (a report from before the click, read late on a busy machine, cannot undo it), at most this
# long (s): a refused or lost request shows again
TOGGLE_HOLD = 5.0


class WebView(GuardedNode):
    def __init__(self, **kwargs):
        super().__init__(
            'web_view', automatically_declare_parameters_from_overrides=True, **kwargs
        )
        from ..view.page import Page  # noqa: PLC0415 - viser: only when the node runs

        self.ns = str(param(self, 'controller', '/orca_controller')).rstrip('/')
        self.floating = bool(param(self, 'floating_base', False))
        camera = (
            list(param(self, 'camera_position', [1.4, -1.4, 1.1])),
            list(param(self, 'camera_look_at', [0.0, 0.0, 0.4])),
            np.radians(float(param(self, 'camera_fov', 50.0))),
        )
        if len(camera[0]) != 3 or len(camera[1]) != 3:
            raise ValueError('camera_position and camera_look_at take 3 values each')
        self.page = Page(
            str(param(self, 'host', '127.0.0.1')), int(param(self, 'port', 8080)),
            float(param(self, 'gizmo_scale', 0.2)), camera,
        )
        self.get_logger().info(f'web view at {self.page.url}')
        print(f'web view: {self.page.url}', flush=True)
        self.lock = threading.Lock()
        self.book = GizmoBook(min_period=0.05)
        self.scene = None
        self._description = None
        self._positions: dict = {}
        self._base_pose = None
        self._state_changed = False
        self._target_pubs: dict = {}
        self._set_active: dict = {}  # task name -> SetBool client
        self._error_shown: dict = {}  # task name -> when its error was last shown
        self._toggled: dict = {}  # task name -> (when, value) a tab toggled it (it ramps)
        self._obstacles: dict = {}  # name -> (shape, size, pose, frame: None = the world)
        self.solve_times = SolveTimeHistory(float(param(self, 'plot_window', 30.0)))
        self._pattern = re.compile(rf'^{re.escape(self.ns)}/tasks/([^/]+)/current_pose$')
        urdf_path = str(param(self, 'urdf_path', ''))
        if urdf_path:
            from ..configuration import resolve_urdf_path  # noqa: PLC0415

            path = resolve_urdf_path(urdf_path)
            with open(path) as fh:
                self._load(fh.read(), path)
        self.create_subscription(
            String, 'robot_description', lambda m: self._load(m.data, ''), DESCRIPTION_QOS
        )
        self.create_subscription(JointState, 'joint_states', self._on_state,
                                 qos_profile_sensor_data)
        if self.floating:
            self.create_subscription(Odometry, 'odom', self._on_odom, qos_profile_sensor_data)
        self.create_subscription(
            MarkerArray, f'{self.ns}/obstacles', self._on_obstacles, DEFAULT_QOS
        )
        self._obstacle_pub = self.create_publisher(
            MarkerArray, f'{self.ns}/obstacles', DEFAULT_QOS
        )
        self._obstacle_msgs: dict = {}  # name -> the last ADD marker (a drag sends it moved)
        self._obstacle_sent: dict = {}  # name -> when a drag last sent it
        self.create_subscription(
            MarkerArray, f'{self.ns}/markers', self._on_markers, DEFAULT_QOS
        )
        self.create_subscription(DiagnosticArray, '/diagnostics', self._on_diagnostics, 10)
        self.create_timer(1.0 / float(param(self, 'rate', 30.0)), self._redraw)
        self.create_timer(0.5, self._discover_tasks)
        self._discover_tasks()

    # ------------------------------------------------------------------ robot
    def _load(self, text: str, path: str) -> None:
        if text == self._description:
            return
        from ..view.robot_scene import RobotScene  # noqa: PLC0415

        try:
            scene = RobotScene(text, path, self.floating)
        except (ValueError, OSError) as exc:
            self.say('error', 'description', f'robot description not shown: {exc}')
            return
        with self.lock:
            self.scene, self._description = scene, text
            self._state_changed = True
            self.page.set_robot(scene.visuals)
        joints = ', '.join(scene.joint_names)
        self.get_logger().info(f'robot: {len(scene.visuals)} visuals, joints {joints}')

    def _on_state(self, msg: JointState) -> None:
        if len(msg.position) != len(msg.name):
            self.say('warning', 'state', 'joint state ignored: names and positions differ in size')
            return
        with self.lock:
            self._positions.update(zip(msg.name, msg.position))
            self._state_changed = True

    def _on_odom(self, msg: Odometry) -> None:
        p, o = msg.pose.pose.position, msg.pose.pose.orientation
        with self.lock:
            self._base_pose = (np.array([p.x, p.y, p.z]), np.array([o.x, o.y, o.z, o.w]))
            self._state_changed = True

    def _redraw(self) -> None:
        with self.lock:
            if self.scene is None or not self._state_changed:
                return
            self._state_changed = False
            self.scene.update(self._positions, self._base_pose)
            poses = self.scene.visual_poses()
        self.page.place_robot(poses)
        for name, (shape, size, pose, frame) in list(self._obstacles.items()):
            if frame is not None:  # on a link (or the base): moves with it
                self.page.set_obstacle(name, shape, size, self._world_from(frame) @ pose,
                                       self._on_obstacle_drag)

    # ------------------------------------------------------------------ obstacles
    def _on_obstacles(self, msg: MarkerArray) -> None:
        base = self.scene.root_frame if self.scene is not None else ''
        for m in msg.markers:
            name = f'{m.ns}/{m.id}'
            try:
                action = marker_action(m, self._obstacles)
                if action != Marker.ADD:
                    for n in list(self._obstacles) if action == Marker.DELETEALL else [name]:
                        del self._obstacles[n]
                        self.page.remove_obstacle(n)
                    continue
                shape, size, pose, frame = marker_obstacle(m, base)
                world = self._world_from(frame) @ pose if frame else pose
                self._obstacles[name] = (shape, size, pose, frame)
                self._obstacle_msgs[name] = m
                self.page.set_obstacle(name, shape, size, world, self._on_obstacle_drag)
            except (ValueError, KeyError) as exc:
                self.say('warning', f'obstacle:{name}',
                         f"obstacle marker '{name}' not shown: {exc}")

    # ------------------------------------------------------------------ controller's markers
    def _on_markers(self, msg: MarkerArray) -> None:
        """Draw the controller's ``~/markers`` (CoM, support polygon, contact forces)."""
        for m in msg.markers:
            name = f'{m.ns}/{m.id}'
            try:
                if m.action == Marker.DELETEALL:
                    for n in self.page.marker_names():
                        self.page.remove_marker(n)
                elif m.action == Marker.DELETE:
                    self.page.remove_marker(name)
                else:
                    self._draw_marker(name, m)
            except (ValueError, KeyError) as exc:
                self.say('warning', f'marker:{name}', f"marker '{name}' not shown: {exc}")

    def _draw_marker(self, name: str, m: Marker) -> None:
        frame = m.header.frame_id
        world = np.eye(4) if frame in ('', 'world') else self._world_from(frame)
        T = world @ pose_to_matrix(m.pose)
        pts = np.array([[p.x, p.y, p.z] for p in m.points], dtype=float).reshape(-1, 3)
        pts = pts @ T[:3, :3].T + T[:3, 3]
        rgba = (m.color.r, m.color.g, m.color.b, m.color.a)
        if m.type == Marker.SPHERE:
            self.page.set_marker_sphere(name, T[:3, 3], 0.5 * m.scale.x, rgba)
        elif m.type == Marker.LINE_STRIP and len(pts) >= 2:
            self.page.set_marker_line(name, pts, m.scale.x, rgba)
        elif m.type == Marker.ARROW:
            if len(pts) == 2:  # start and end; scale: shaft and head diameters
                start, end = pts
                shaft, head = m.scale.x, m.scale.y
            else:  # along the pose's x axis: scale = length, shaft, head
                start, end = T[:3, 3], T[:3, 3] + m.scale.x * T[:3, 0]
                shaft, head = m.scale.y, m.scale.z
            self.page.set_marker_arrow(name, start, end, shaft, head, rgba)
        else:
            raise ValueError(f'type {m.type} with {len(pts)} points is not drawn '
                             '(SPHERE, LINE_STRIP, ARROW are)')

    def _on_obstacle_drag(self, name: str, phase: str, world_pose: np.ndarray) -> None:
        """Send a drag of an obstacle (viser's thread) as its marker moved, to ``~/obstacles``."""
        now = time.monotonic()
        m, held = self._obstacle_msgs.get(name), self._obstacles.get(name)
        if m is None or held is None or phase == 'start' or (
            phase != 'end' and now - self._obstacle_sent.get(name, -1.0) < self.book.min_period
        ):
            return
        self._obstacle_sent[name] = now
        try:
            local = np.linalg.solve(self._world_from(held[3]), world_pose)
        except ValueError as exc:  # its link gone with a new robot description
            self.say('warning', f'obstacle:{name}', f"obstacle '{name}' not sent: {exc}")
            return
        moved = copy.deepcopy(m)
        moved.action = Marker.ADD
        moved.header.stamp = self.get_clock().now().to_msg()
        matrix_to_pose(local, moved.pose)
        self._obstacle_pub.publish(MarkerArray(markers=[moved]))

    def _world_from(self, frame: str) -> np.ndarray:
        """World pose of a frame of the model ('' or unknown model: the identity)."""
        if self.scene is None or not frame:
            return np.eye(4)
        return self.scene.frame_pose(frame)

    # ------------------------------------------------------------------ tasks
    def _discover_tasks(self) -> None:
        for topic, types in self.get_topic_names_and_types():
            m = self._pattern.match(topic)
            if m is None or POSE_TYPE not in types or m.group(1) in self._target_pubs:
                continue
            name = m.group(1)
            base = f'{self.ns}/tasks/{name}'
            self._target_pubs[name] = self.create_publisher(
                PoseStamped, f'{base}/target_pose', DEFAULT_QOS
            )
            self.create_subscription(
                PoseStamped, f'{base}/current_pose', lambda msg, n=name: self._on_current(n, msg),
                DEFAULT_QOS,
            )
            self.create_subscription(
                PoseStamped, f'{base}/target_pose', lambda msg, n=name: self._on_target(n, msg),
                DEFAULT_QOS,
            )
            self.create_subscription(
                Float64MultiArray, f'{base}/error', lambda msg, n=name: self._on_error(n, msg),
                DEFAULT_QOS,
            )
            self._set_active[name] = self.create_client(SetBool, f'{base}/set_active')
            self.page.add_task_controls(name, self._on_active_toggled)
            self.get_logger().info(f"task '{name}': its target draggable on the page")

    def _on_current(self, name: str, msg: PoseStamped) -> None:
        with self.lock:
            frame = msg.header.frame_id
            world_from_frame = self._world_from(frame)
            first = self.book.on_current(name, pose_to_matrix(msg.pose), frame, world_from_frame)
            current, target = self.book.tasks[name].current, self.book.tasks[name].target
        if first or not self.page.has_task(name):
            self.page.add_task(name, target, self._on_drag)
        self.page.set_current(name, current)

    def _on_target(self, name: str, msg: PoseStamped) -> None:
        with self.lock:
            frame = msg.header.frame_id or self.book.task(name).frame_id
            try:
                world = self._world_from(frame) @ pose_to_matrix(msg.pose)
            except ValueError as exc:
                self.say('warning', f'target:{name}', f"target of '{name}' not shown: {exc}")
                return
            moved = self.book.on_target(name, world)
        if moved and self.page.has_task(name):
            self.page.set_target(name, world)

    def _on_error(self, name: str, msg: Float64MultiArray) -> None:
        now = time.monotonic()
        if now - self._error_shown.get(name, -1.0) < ERROR_PERIOD:
            return
        self._error_shown[name] = now
        e = np.asarray(msg.data, dtype=float)
        if e.size == 6:
            angle = np.degrees(np.linalg.norm(e[3:]))
            text = f'{np.linalg.norm(e[:3]) * 1e3:.2f} mm, {angle:.2f} deg'
        else:
            text = f'{np.linalg.norm(e):.4f}'
        self.page.set_task_error(name, text)

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            if 'active_tasks' not in values or not status.name.startswith(
                self.ns.rsplit('/', 1)[-1] + ':'
            ):
                continue
            stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
            if self.solve_times.add(stamp, values):
                self.page.set_solve_times(*self.solve_times.arrays(), self.solve_times.title(),
                                          self.solve_times.window)
            active = set(filter(None, values['active_tasks'].split(',')))
            now = time.monotonic()
            for name in self._set_active:
                clicked = self._toggled.get(name)
                if clicked is not None:
                    at, value = clicked
                    if (name in active) != value and now - at <= TOGGLE_HOLD:
                        continue  # the controller has not taken the click yet
                    self._toggled.pop(name, None)
                self.page.set_task_active(name, name in active)

    def _on_active_toggled(self, name: str, value: bool) -> None:
        """Ask the controller to (de)activate a task (viser's thread); it ramps it."""
        client = self._set_active[name]
        if not client.service_is_ready():
            self.say('warning', f'set_active:{name}', f"task '{name}': no set_active service")
            return
        self._toggled[name] = (time.monotonic(), value)
        client.call_async(SetBool.Request(data=value))
        self.get_logger().info(f"task '{name}': {'activate' if value else 'deactivate'} asked")

    def _on_drag(self, name: str, phase: str, world_pose: np.ndarray) -> None:
        """Send a drag on the page (viser's thread) as a target on the controller's topic."""
        with self.lock:
            frame = self.book.task(name).frame_id
            pose = self.book.on_drag(name, phase, world_pose, time.monotonic(),
                                     self._world_from(frame))
        if pose is None:
            return
        msg = PoseStamped()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = frame
        matrix_to_pose(pose, msg.pose)
        self._target_pubs[name].publish(msg)

    def destroy_node(self):
        self.page.stop()
        return super().destroy_node()


def main(args=None) -> int:
    try:
        optional_import('viser', 'web_view')
    except MissingDependency as exc:
        print(exc, file=sys.stderr)
        return 1
    return run_node(WebView, args)


if __name__ == '__main__':
    sys.exit(main())
