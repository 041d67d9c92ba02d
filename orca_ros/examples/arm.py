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
What the arm examples need to know about an arm, read from its model.

The examples were written for the shipped lwr (``link_7`` on ``base_link``, 7 joints, targets in
metres). For any serial arm given by its URDF they take:

- the base frame: the URDF's root link (``RobotModel``'s default base frame);
- the tool frame: the tip of the kinematic chain, the last link fixed on the joint that ends it
  (before a gripper's fingers) (lwr: ``link_7``; UR5 of example-robot-data: ``tool0``; iiwa:
  ``lbr_iiwa_link_7``);
- a start posture: the lwr's, joint by joint (zeros for joints the lwr does not have), clipped
  into the joint limits with a margin of 5 % of each range;
- targets: the lwr's points moved into this arm's reach sphere (:mod:`orca_ros.robot.reach`): the
  same place relative to the centre of the tool's reach, scaled by the ratio of the radii.
  Orientations stay as written (for the lwr, the UR5 and the iiwa the tool's z axis is the
  approach direction). On the lwr every one of these is the identity.

``--base-frame`` / ``--tool-frame`` override the guess.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pinocchio as pin

from .. import default_urdf_path, RobotModel
from ..robot.reach import robot_reach

#: the lwr's frames, for which the examples' numbers are written
LWR_BASE, LWR_TOOL = 'base_link', 'link_7'


def add_frame_args(parser) -> None:
    """Add ``--base-frame`` and ``--tool-frame`` (default: derived from the URDF)."""
    parser.add_argument(
        '--base-frame', default=None, help="base frame (default: the URDF's root link)"
    )
    parser.add_argument(
        '--tool-frame',
        default=None,
        help='controlled frame (default: the tip of the kinematic chain)',
    )


def tool_frame(robot) -> str:
    """
    Return the tip of the chain: the last link on the joint that ends it.

    That joint is the one without children, or, where the chain branches at its end (a gripper's
    fingers), the last joint all the branches share (the Panda's hand: ``panda_hand_tcp``).
    """
    model = robot.model
    parents = set(model.parents[1:])
    leaves = [j for j in range(1, model.njoints) if j not in parents]
    shared = set.intersection(*(set(model.supports[j]) for j in leaves)) if leaves else {0}
    end = leaves[0] if len(leaves) == 1 else max(shared)
    bodies = [
        f.name for f in model.frames if f.parentJoint == end and f.type == pin.FrameType.BODY
    ]
    return bodies[-1]


def posture(robot, q_lwr, margin: float = 0.05, clearance: float = 0.05) -> np.ndarray:
    """
    Return the lwr posture ``q_lwr`` for this arm, inside its joint limits, above its base.

    Joint by joint (zeros past the lwr's seven, dropped past this arm's), clipped to ``margin``
    of each joint's range from its limits. Arms turn their joints the other way round too (the
    UR5's shoulder lowers the arm where the lwr's raises it): when a link the second joint or a
    later one moves comes within ``clearance`` [m] of the base's xy plane (the floor), the mirrored
    posture -q is taken, or q = 0 (clipped) when that dips too.
    """
    n = robot.get_nr_of_degrees_of_freedom()
    q = np.zeros(n)
    q_lwr = np.asarray(q_lwr, dtype=float)
    m = min(n, q_lwr.size)
    q[:m] = q_lwr[:m]
    lo, hi = robot.get_joint_position_limits()
    room = margin * np.where(np.isfinite(hi - lo), hi - lo, 0.0)
    candidates = [np.clip(c, lo + room, hi - room) for c in (q, 0.0 - q, np.zeros(n))]
    for c in candidates:
        if _lowest_link(robot, c) >= clearance:
            return c
    return candidates[0]


def _lowest_link(robot, q) -> float:
    """Height over the base's plane of the lowest link the second joint or a later one moves."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    fid = robot.get_frame_id(robot.get_base_frame())
    base = data.oMf[fid] if fid >= 0 else pin.SE3.Identity()
    heights = [
        base.actInv(data.oMf[i]).translation[2]
        for i, f in enumerate(model.frames)
        if f.type == pin.FrameType.BODY and f.parentJoint >= 2
    ]
    return min(heights) if heights else np.inf


@lru_cache(maxsize=1)
def _lwr_reach():
    lwr = RobotModel()
    lwr.load_model_from_file(default_urdf_path())
    lwr.set_base_frame(LWR_BASE)
    return robot_reach(lwr, LWR_TOOL)


def to_reach(robot, tool: str, point) -> np.ndarray:
    """
    Move a point written for the lwr's tool into ``tool``'s reach (the robot's base frame).

    Same offset from the centre of the reach sphere, scaled by the ratio of the radii; the point
    itself on the lwr.
    """
    point = np.asarray(point, dtype=float)
    ref, own = _lwr_reach(), robot_reach(robot, tool)
    if np.allclose(own.center, ref.center, rtol=0, atol=1e-12) and own.radius == ref.radius:
        return point.copy()
    return own.center + (point - ref.center) * (own.radius / ref.radius)


def shoulder_frame(robot) -> str:
    """Return the link the second joint moves (lwr: ``link_2``), where the arm's length starts."""
    model = robot.model
    joint = min(2, model.njoints - 1)
    bodies = [
        f.name for f in model.frames if f.parentJoint == joint and f.type == pin.FrameType.BODY
    ]
    return bodies[0]
