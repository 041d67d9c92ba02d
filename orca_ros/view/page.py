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
The page on viser: the robot's meshes, and per Cartesian task a target gizmo and its current pose.

Viser keeps the scene on the server and sends it whole to each tab that connects, so every tab
(and a reloaded one) shows the current state; a drag in one tab moves the gizmo in the others.
Viser is an optional dependency, imported through :func:`orca_ros.utils.optional_import`.
"""

from __future__ import annotations

import numpy as np

from . import shapes
from .gizmos import to_matrix, to_position_wxyz
from ..utils.optional_import import optional_import

CURRENT_COLOR = (230, 0, 230)  # the current pose's marker: a magenta ball with axes
OBSTACLE_COLOR = (90, 120, 230)  # obstacles: blue, half transparent


def _rgb(rgba) -> tuple[int, int, int]:
    return tuple(int(round(255 * min(max(c, 0.0), 1.0))) for c in rgba[:3])


class Page:
    def __init__(self, host: str = '127.0.0.1', port: int = 8080, gizmo_scale: float = 0.2,
                 camera=None):
        """
        Start the page's server (viser picks the next free port when ``port`` is taken).

        ``camera``: (position, look_at, vertical field of view [rad]) of a tab that connects,
        None: viser's default.
        """
        viser = optional_import('viser', 'web_view')
        self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self.server.scene.set_up_direction('+z')
        if camera is not None:
            position, look_at, fov = camera
            cam = self.server.initial_camera
            cam.position, cam.look_at, cam.fov = tuple(position), tuple(look_at), float(fov)
        self.gizmo_scale = float(gizmo_scale)
        self._meshes: list = []
        self._tasks: dict = {}  # name -> (gizmo handle, current-pose frame handle)
        self._obstacles: dict = {}  # name -> (shape, size, mesh handle, gizmo handle)
        self._dragging: set = set()  # obstacles a tab drags now
        self._controls: dict = {}  # task name -> (active checkbox, error text)
        self._solve_plot = None  # the solve times' uPlot chart, made at the first report
        self._markers: dict = {}  # name -> (kind, handle): the controller's ~/markers
        self.server.scene.add_grid('/grid', width=2.0, height=2.0, cell_size=0.1)

    @property
    def url(self) -> str:
        host = self.server.get_host()
        host = 'localhost' if host in ('0.0.0.0', '::', '') else host
        return f'http://{host}:{self.server.get_port()}'

    def set_robot(self, visuals) -> None:
        """Replace the robot's meshes (:class:`~.robot_scene.Visual` list)."""
        with self.server.atomic():
            for handle in self._meshes:
                handle.remove()
            self._meshes = [
                self.server.scene.add_mesh_simple(
                    f'/robot/{k}_{v.name}', v.vertices, v.faces, color=_rgb(v.rgba),
                    opacity=None if v.rgba[3] >= 1.0 else float(v.rgba[3]), side='double',
                )
                for k, v in enumerate(visuals)
            ]

    def place_robot(self, poses) -> None:
        """Move the meshes to their world poses (4x4 each, in the order of :meth:`set_robot`)."""
        with self.server.atomic():
            for handle, T in zip(self._meshes, poses):
                handle.position, handle.wxyz = to_position_wxyz(T)

    def has_task(self, name: str) -> bool:
        return name in self._tasks

    def add_task(self, name: str, pose: np.ndarray, on_drag) -> None:
        """
        Add a task's target gizmo and current-pose marker at ``pose`` (world).

        ``on_drag(name, phase, world_pose)`` is called for each drag event of any tab.
        """
        position, wxyz = to_position_wxyz(pose)
        gizmo = self.server.scene.add_transform_controls(
            f'/tasks/{name}/target', scale=self.gizmo_scale, position=position, wxyz=wxyz,
            depth_test=False,
        )
        current = self.server.scene.add_frame(
            f'/tasks/{name}/current', axes_length=0.4 * self.gizmo_scale,
            axes_radius=0.02 * self.gizmo_scale, origin_radius=0.2 * self.gizmo_scale,
            origin_color=CURRENT_COLOR, position=position, wxyz=wxyz,
        )

        def moved(event):
            h = event.target
            on_drag(name, event.phase, to_matrix(h.position, h.wxyz))

        gizmo.on_update(moved)
        self._tasks[name] = (gizmo, current)

    def add_task_controls(self, name: str, on_active) -> None:
        """
        Add a task's panel entries: an ``active`` checkbox and its error (read only).

        ``on_active(name, value)`` is called when a tab toggles the checkbox.
        """
        with self.server.gui.add_folder(f'task {name}'):
            active = self.server.gui.add_checkbox(f'{name} active', True)
            error = self.server.gui.add_text(f'{name} error', '', disabled=True)
        # a tab's click only (client None: the node set the value, from the diagnostics)
        active.on_update(
            lambda event: event.client is not None and on_active(name, bool(event.target.value))
        )
        self._controls[name] = (active, error)

    def has_task_controls(self, name: str) -> bool:
        return name in self._controls

    def set_task_active(self, name: str, value: bool) -> None:
        box = self._controls[name][0]
        if box.value != value:
            box.value = value

    def set_task_error(self, name: str, text: str) -> None:
        self._controls[name][1].value = text

    def set_solve_times(self, t, median, p99, title: str, window: float = 30.0) -> None:
        """
        Plot the controller's solve times [us] against time [s] (:mod:`.solve_times`).

        The time axis spans the last ``window`` seconds (fixed when the plot is made).
        """
        data = tuple(np.asarray(a, dtype=float) for a in (t, median, p99))
        if self._solve_plot is None:
            # folded at first: open, it would cover part of the scene
            with self.server.gui.add_folder('solve time', expand_by_default=False):
                self._solve_plot = self.server.gui.add_uplot(
                    data,
                    (
                        {'label': 't [s]'},
                        {'label': 'median [us]', 'stroke': '#1f77b4', 'width': 2},
                        {'label': 'p99 [us]', 'stroke': '#d62728', 'width': 1},
                    ),
                    title=title, height=140,
                    scales={'x': {'time': False, 'range': (-window, 0.0)}},
                )
            return
        with self.server.atomic():
            self._solve_plot.data = data
            self._solve_plot.title = title

    def set_current(self, name: str, pose: np.ndarray) -> None:
        self._tasks[name][1].position, self._tasks[name][1].wxyz = to_position_wxyz(pose)

    def set_target(self, name: str, pose: np.ndarray) -> None:
        self._tasks[name][0].position, self._tasks[name][0].wxyz = to_position_wxyz(pose)

    def set_obstacle(self, name: str, shape: str, size, pose: np.ndarray, on_drag=None) -> None:
        """
        Show an obstacle (sphere [r], box [x, y, z], cylinder [r, length]) at a world pose.

        The shape hangs from a gizmo (moves only: arrows and planes); ``on_drag(name, phase,
        world_pose)`` is called for each drag event of any tab. While a tab drags it, poses
        given here are not shown (the hand on the page wins until it lets go).
        """
        old = self._obstacles.get(name)
        if old is None:
            controls = self.server.scene.add_transform_controls(
                f'/obstacles/{name}', scale=max(0.1, 2.0 * float(max(size))),
                disable_rotations=True, depth_test=False,
            )

            def moved(event):
                h = event.target
                if event.phase == 'start':
                    self._dragging.add(name)
                elif event.phase == 'end':
                    self._dragging.discard(name)
                if on_drag is not None:
                    on_drag(name, event.phase, to_matrix(h.position, h.wxyz))

            controls.on_update(moved)
            old = (None, None, None, controls)
        if old[:2] != (shape, list(size)):
            if old[2] is not None:
                old[2].remove()
            verts, faces = {
                'sphere': lambda: shapes.sphere(size[0]),
                'box': lambda: shapes.box(size),
                'cylinder': lambda: shapes.cylinder(size[0], size[1]),
            }[shape]()
            mesh = self.server.scene.add_mesh_simple(
                f'/obstacles/{name}/shape', verts, faces, color=OBSTACLE_COLOR, opacity=0.6,
                side='double',
            )
            old = (shape, list(size), mesh, old[3])
        self._obstacles[name] = old
        if name not in self._dragging:
            old[3].position, old[3].wxyz = to_position_wxyz(pose)

    def remove_obstacle(self, name: str) -> None:
        old = self._obstacles.pop(name, None)
        self._dragging.discard(name)
        if old is not None:
            old[2].remove()
            old[3].remove()

    def set_marker_sphere(self, name: str, centre, radius: float, rgba) -> None:
        """Show a ball (a marker's SPHERE: the CoM) at a world point."""
        handle = self._marker_handle(name, ('sphere', float(radius)), lambda: (
            self.server.scene.add_mesh_simple(
                f'/markers/{name}', *shapes.sphere(radius), color=_rgb(rgba), side='double')
        ))
        handle.position = tuple(float(c) for c in centre)

    def set_marker_line(self, name: str, points, width: float, rgba) -> None:
        """Show a polyline (a marker's LINE_STRIP: the support polygon) through world points."""
        pts = np.asarray(points, dtype=float)
        segments = np.stack((pts[:-1], pts[1:]), axis=1)
        handle = self._marker_handle(name, ('line', len(segments)), lambda: (
            self.server.scene.add_line_segments(
                f'/markers/{name}', segments, _rgb(rgba), thickness=max(float(width), 1e-3))
        ))
        handle.points = segments

    def set_marker_arrow(self, name: str, start, end, shaft: float, head: float, rgba) -> None:
        """Show an arrow (a marker's ARROW: a contact force) from ``start`` to ``end`` (world)."""
        start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
        verts, faces = shapes.arrow(np.linalg.norm(end - start), 0.5 * shaft, 0.5 * head,
                                    1.5 * head)
        handle = self._marker_handle(name, ('arrow',), lambda: (
            self.server.scene.add_mesh_simple(
                f'/markers/{name}', verts, faces, color=_rgb(rgba), side='double')
        ))
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = shapes.z_onto(end - start), start
        with self.server.atomic():
            handle.vertices = verts
            handle.position, handle.wxyz = to_position_wxyz(T)

    def _marker_handle(self, name: str, key: tuple, make):
        old = self._markers.get(name)
        if old is not None and old[0] == key:
            return old[1]
        if old is not None:
            old[1].remove()
        handle = make()
        self._markers[name] = (key, handle)
        return handle

    def remove_marker(self, name: str) -> None:
        old = self._markers.pop(name, None)
        if old is not None:
            old[1].remove()

    def marker_names(self) -> list:
        return list(self._markers)

    def clients(self) -> int:
        return len(self.server.get_clients())

    def stop(self) -> None:
        self.server.stop()
