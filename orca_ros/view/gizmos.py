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
Bookkeeping of the target gizmos, one per Cartesian task (no ROS, no viser).

A task's gizmo appears at its current pose (the controller's ``current_pose``, in its base frame)
and shows its target from then on: a drag on the page becomes a target in the frame the controller
reports the task in (the page sends it through the controller's own topic and checks), at most
one per ``min_period`` during a drag and always at its end; a target sent by anyone else moves the
gizmo, except while a drag is under way (the hand on the page wins until it lets go).
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math

import numpy as np
import pinocchio as pin


def to_matrix(position, wxyz) -> np.ndarray:
    """4x4 pose from a position and a quaternion (w, x, y, z)."""
    w, x, y, z = (float(c) for c in wxyz)
    T = np.eye(4)
    T[:3, :3] = pin.Quaternion(w, x, y, z).normalized().matrix()
    T[:3, 3] = np.asarray(position, dtype=float)
    return T


def to_position_wxyz(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position and quaternion (w, x, y, z) of a 4x4 pose."""
    x, y, z, w = pin.Quaternion(np.asarray(T[:3, :3], dtype=float)).coeffs()
    return np.array(T[:3, 3], dtype=float), np.array([w, x, y, z])


@dataclass
class TaskGizmo:
    name: str
    frame_id: str = ''  # the frame the controller reports the task's pose in
    current: np.ndarray | None = None  # world pose of the task's frame
    target: np.ndarray | None = None  # world pose the gizmo shows
    dragging: bool = False
    last_sent: float = -math.inf
    sent: list = field(default_factory=list)  # poses sent (in frame_id), the last few


class GizmoBook:
    def __init__(self, min_period: float = 0.05):
        self.min_period = float(min_period)
        self.tasks: dict[str, TaskGizmo] = {}

    def task(self, name: str) -> TaskGizmo:
        if name not in self.tasks:
            self.tasks[name] = TaskGizmo(name)
        return self.tasks[name]

    def on_current(self, name: str, pose: np.ndarray, frame_id: str,
                   world_from_frame: np.ndarray) -> bool:
        """
        Take a current pose (in ``frame_id``, placed in the world by ``world_from_frame``).

        Returns whether the target gizmo appears with it (a task's first pose: its target is
        where it is until someone sends one).
        """
        g = self.task(name)
        g.frame_id = frame_id
        g.current = world_from_frame @ pose
        if g.target is None:
            g.target = g.current.copy()
            return True
        return False

    def on_target(self, name: str, world_pose: np.ndarray) -> bool:
        """Take a target someone sent (world pose); whether the gizmo moves to it."""
        g = self.task(name)
        if g.dragging or not np.all(np.isfinite(world_pose)):
            return False
        g.target = np.array(world_pose, dtype=float)
        return True

    def on_drag(self, name: str, phase: str, world_pose: np.ndarray, now: float,
                world_from_frame: np.ndarray):
        """
        Take a drag event (``start``, ``update``, ``end``) with the gizmo's world pose.

        Returns the pose to send in the task's frame (its ``frame_id``), or None: nothing to send
        (too soon after the last, or the task's frame not known yet).
        """
        g = self.task(name)
        g.dragging = phase != 'end'
        if g.current is None or not np.all(np.isfinite(world_pose)):
            return None
        g.target = np.array(world_pose, dtype=float)
        if phase == 'start' or (phase == 'update' and now - g.last_sent < self.min_period):
            return None
        g.last_sent = now
        pose = np.linalg.solve(world_from_frame, g.target)
        g.sent = (g.sent + [pose])[-10:]
        return pose
