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
How far a frame can get from a task's root: a sphere from the kinematic chain, no joint limits.

A revolute (or spherical) joint turns everything after it about its own origin. Along the chain
from the root to the frame, the first moving joint's origin is fixed in the root's frame, and the
frame is at most the sum of the chain's link lengths from it (the lengths of the URDF joint
placements after that joint, plus the frame's own offset), plus the stroke of every prismatic joint
on the way (its largest absolute limit). That sphere holds every pose the frame can take, whatever
the joint limits: a target outside it is out of reach for sure (a target inside may still be, by
the joint limits or the orientation asked). A free-flyer, planar or unlimited prismatic joint on
the chain makes the reach unbounded (no target is judged). When the root itself hangs on other
joints than the frame (a tree), the sphere is centred on the root and grown by how far the root can
get from the chains' common part. Joints locked in the model (a gripper's) count as moving: their
welding changes with the measurements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

# joints that turn about their origin (distances to it are kept); prismatic ones slide
_TURNING = ('JointModelR', 'JointModelSpherical', 'JointModelUniversal')
_SLIDING = ('JointModelP',)


@dataclass(frozen=True)
class Reach:
    """Every position of ``frame`` in ``root``'s frame is within ``radius`` of ``center``."""

    root: str
    frame: str
    center: np.ndarray
    radius: float  # inf: unbounded

    def distance(self, position) -> float:
        """Distance of a position (``root``'s frame) from the centre."""
        return float(np.linalg.norm(np.asarray(position, dtype=float)[:3] - self.center))

    def beyond(self, position) -> float | None:
        """Return the distance from the centre when ``position`` is out of reach, else None."""
        d = self.distance(position)
        return d if d > self.radius else None

    def refusal(self, task: str, position) -> str | None:
        """Return the warning for a target of ``task`` at ``position`` out of reach, else None."""
        d = self.beyond(position)
        if d is None:
            return None
        return (
            f"target of task '{task}' out of reach: {self.frame} asked {d:.3f} m from the centre "
            f'of its reach, which is {self.radius:.3f} m (the chain from {self.root}); target '
            'ignored, the task holds its previous target'
        )


def _stroke(model: pin.Model, j: int) -> float:
    """How far joint j moves a point at its origin: 0 turning, the stroke sliding, else inf."""
    jm = model.joints[j]
    kind = jm.shortname()
    if kind.startswith(_TURNING):
        return 0.0
    if kind.startswith(_SLIDING) and jm.nq == 1:
        lo, hi = model.lowerPositionLimit[jm.idx_q], model.upperPositionLimit[jm.idx_q]
        s = max(abs(lo), abs(hi))
        return float(s) if np.isfinite(s) and s < 1e10 else np.inf
    return np.inf


def _branch(model: pin.Model, joints: list[int], tip: np.ndarray):
    """
    Centre and radius of a point ``tip`` (in the last joint's frame) after ``joints``.

    Centre in the frame before the first of ``joints`` (None, None without joints).
    """
    if not joints:
        return None, None
    radius = float(np.linalg.norm(tip)) + sum(_stroke(model, j) for j in joints)
    radius += sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in joints[1:])
    return np.array(model.jointPlacements[joints[0]].translation), radius


def _attachment(model: pin.Model, name: str):
    """(parent joint, placement) of a frame; the universe at the identity for 'world'."""
    if name == 'world' and not model.existFrame(name):
        return 0, pin.SE3.Identity()
    f = model.frames[model.getFrameId(name)]
    return f.parentJoint, f.placement


def chain_reach(model: pin.Model, root: str, frame: str) -> Reach:
    """Return the reach sphere of ``frame`` in ``root``'s frame (frame names of ``model``)."""
    for name in (root, frame):
        if name != 'world' and not model.existFrame(name):
            raise ValueError(f"reach: unknown frame '{name}'")
    jr, Mr = _attachment(model, root)
    jf, Mf = _attachment(model, frame)
    up, down = list(model.supports[jr]), list(model.supports[jf])
    common = max(set(up) & set(down))  # ids grow along a chain: the deepest shared joint
    up, down = [j for j in up if j > common], [j for j in down if j > common]
    c, r = _branch(model, down, Mf.translation)
    if c is None:  # the frame is fixed on the common part
        c, r = np.array(Mf.translation), 0.0
    if not up:  # the root too: the sphere is fixed in its frame
        return Reach(root, frame, Mr.actInv(c), r)
    cr, rr = _branch(model, up, Mr.translation)
    return Reach(root, frame, np.zeros(3), r + float(np.linalg.norm(c - cr)) + rr)


def robot_reach(robot, frame: str, root: str | None = None) -> Reach:
    """
    Return the reach of ``frame`` from ``root`` (the base frame by default) of a RobotModel.

    From its full model (locked joints move).
    """
    return chain_reach(robot.get_full_model(), root or robot.get_base_frame(), frame)


def task_reaches(robot, tasks: dict) -> dict:
    """Name -> :class:`Reach` of the Cartesian tasks among ``tasks`` (name -> task)."""
    from ..task import CartesianTask  # noqa: PLC0415 - the robot package comes before the tasks

    return {
        n: robot_reach(robot, t.get_control_frame())
        for n, t in tasks.items()
        if isinstance(t, CartesianTask)
    }
