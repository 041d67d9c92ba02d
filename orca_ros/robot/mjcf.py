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
Robots described in MJCF (MuJoCo's format), read by Pinocchio's parser.

The MuJoCo Menagerie's robots exist only as MJCF. Pinocchio makes each body a frame (its name)
and each hinge or slide joint a joint (with its ``armature``, which Pinocchio's mass matrix adds as
MuJoCo's does); ``range`` gives the position limits. The torque limits: the joint's
``actuatorfrcrange``, and the ``forcerange`` of the actuators driving the joint (a joint
transmission: |force| * |gear|), the least of them; that is where the Menagerie puts them (on
its ``general`` actuators). MuJoCo's own parser reads the actuators
(:class:`mujoco.MjSpec`: their defaults classes resolved, nothing compiled). MJCF has no velocity
limits (infinite). The floating base: a ``freejoint`` on the root body, or one added at load
(``floating_base``). What the parser refuses (an element it does not know, a file it cannot read)
is a ValueError naming it.

A Menagerie robot by name (:func:`menagerie_path`): the ``mujoco-menagerie`` package's registry,
which downloads the robot on first use (``MENAGERIE_ROOT``: a Menagerie clone instead).
"""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin

from ..utils.optional_import import MissingDependency, optional_import

#: the prefix of a robot model named by its Menagerie name (``menagerie:universal_robots_ur5e``)
MENAGERIE = 'menagerie:'

_ROOT = re.compile(r'^\s*(?:<\?xml[^>]*\?>\s*)?(?:<!--.*?-->\s*)*<(\w+)', re.S)


def is_mjcf(text: str) -> bool:
    """Tell MJCF text (root element ``<mujoco>``) from URDF (``<robot>``)."""
    m = _ROOT.match(text)
    return bool(m) and m.group(1) == 'mujoco'


def build_mjcf_model(path: str, floating_base: bool) -> pin.Model:
    """
    Return Pinocchio's model of the MJCF file ``path``, with a free-flyer root if floating.

    ValueError when the parser refuses the file (its message names the element), when the file's
    root body has a free joint and ``floating_base`` is False (a robot cannot be both), or when
    a free joint is not on the root (not a base).
    """
    try:
        model = pin.buildModelFromMJCF(path)
    except Exception as exc:  # Pinocchio raises ValueError/RuntimeError with its own text
        raise ValueError(f"could not parse MJCF '{path}': {exc}") from exc
    free = [j for j in range(1, model.njoints) if model.joints[j].shortname() ==
            'JointModelFreeFlyer']
    if free and free != [1]:
        raise ValueError(f"MJCF '{path}': free joint '{model.names[free[-1]]}' is not on the "
                         'root body: only a floating base may be free')
    if free and not floating_base:
        raise ValueError(f"MJCF '{path}': its root body has a free joint "
                         f"('{model.names[1]}'): load it with floating_base true")
    if floating_base and not free:
        model = pin.buildModelFromMJCFAndRootJoint(path, pin.JointModelFreeFlyer(), 'root_joint')
    try:  # MuJoCo's parser: what Pinocchio's leaves out
        if not floating_base:
            _place_root_body(model, path)
        limits = actuator_torque_limits(path)
    except MissingDependency:
        raise
    except Exception as exc:  # mujoco raises ValueError with its own text
        raise ValueError(f"could not read MJCF '{path}' with MuJoCo: {exc}") from exc
    for j in range(1, model.njoints):
        limit = limits.get(model.names[j])
        if limit is not None and model.joints[j].nv == 1:
            k = model.joints[j].idx_v
            model.effortLimit[k] = min(model.effortLimit[k], limit)
    return model


def _mujoco():
    """Return MuJoCo, whose parser reads what Pinocchio's does not (MJCF files only)."""
    return optional_import('mujoco', 'an MJCF robot model')


def root_body_placement(path: str) -> tuple[str, pin.SE3] | None:
    """
    Return the name and placement in the world of the MJCF file's fixed root body, if it moves.

    None when the root body is where the world is, has joints (a floating base: its pose is the
    state's), or is not the only body under ``<worldbody>``. MuJoCo resolves the orientation
    (quat, euler, axisangle...), compiling the file only when it is not a plain quaternion.
    """
    mujoco = _mujoco()
    spec = mujoco.MjSpec.from_file(path)
    roots = list(spec.worldbody.bodies)
    if len(roots) != 1 or roots[0].joints:
        return None
    body = roots[0]
    if body.alt.type == mujoco.mjtOrientation.mjORIENTATION_QUAT:
        pos, quat = np.array(body.pos, dtype=float), np.array(body.quat, dtype=float)
    else:
        m = spec.compile()
        pos, quat = m.body_pos[1].copy(), m.body_quat[1].copy()
    quat /= np.linalg.norm(quat)
    if not pos.any() and abs(abs(quat[0]) - 1.0) < 1e-15:
        return None
    rotation = pin.Quaternion(quat[0], quat[1], quat[2], quat[3]).toRotationMatrix()
    return body.name, pin.SE3(rotation, pos)


def _place_root_body(model: pin.Model, path: str) -> None:
    """
    Put the fixed root body where the file places it (Pinocchio's parser leaves it at the world).

    The Menagerie's UR5e turns its base half a turn about z (``quat="0 0 0 -1"``): left at the
    world, the robot's world was not MuJoCo's, and an obstacle placed in the world stood
    elsewhere for the controller than in the simulation. What hangs from the world (the root
    body's frames, its children's joints) moves with it.
    """
    placed = root_body_placement(path)
    if placed is None:
        return
    _, root = placed
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            model.jointPlacements[j] = root * model.jointPlacements[j]
    for f in range(1, len(model.frames)):
        frame = model.frames[f]
        if frame.parentJoint == 0:
            frame.placement = root * frame.placement
            model.frames[f] = frame


def actuator_torque_limits(path: str) -> dict[str, float]:
    """
    Return {joint name: the least torque limit its actuators give} of the MJCF file ``path``.

    An actuator with a joint transmission limits the joint's torque to max|forcerange| * |gear|
    when its force is limited (``forcelimited`` true, or auto with a range given). Actuators on
    other transmissions (tendons, sites) limit no joint here.
    """
    mujoco = _mujoco()
    spec = mujoco.MjSpec.from_file(path)
    limits: dict[str, float] = {}
    for act in spec.actuators:
        lo, hi = float(act.forcerange[0]), float(act.forcerange[1])
        limited = act.forcelimited == mujoco.mjtLimited.mjLIMITED_TRUE or (
            act.forcelimited == mujoco.mjtLimited.mjLIMITED_AUTO and lo < hi)
        if act.trntype != mujoco.mjtTrn.mjTRN_JOINT or not limited or not act.target:
            continue
        limit = max(abs(lo), abs(hi)) * abs(float(act.gear[0]))
        if np.isfinite(limit) and limit > 0.0:
            limits[act.target] = min(limits.get(act.target, np.inf), limit)
    return limits


def mjcf_excluded_pairs(path: str) -> set[tuple[str, str]]:
    """Return the body pairs the MJCF file's ``<contact><exclude>`` elements leave out."""
    return {(e.bodyname1, e.bodyname2) for e in _mujoco().MjSpec.from_file(path).excludes}


def menagerie_path(name: str) -> str:
    """
    Return the MJCF file of the Menagerie robot ``name`` (its robot, not its scene).

    Through the ``mujoco-menagerie`` package: its registry names every robot; the files are
    downloaded once into its cache, or read from a Menagerie clone (``MENAGERIE_ROOT``).
    ValueError naming the cause: the package missing, a name the registry does not know (with
    the nearest ones), a download that failed.
    """
    try:
        mujoco_menagerie = optional_import('mujoco_menagerie', f"'{MENAGERIE}{name}'")
    except MissingDependency as exc:
        raise ValueError(str(exc)) from None
    try:
        robot = mujoco_menagerie.get(name)
        return str(robot.xml(robot.default_model))
    except (mujoco_menagerie.MenagerieError, OSError) as exc:
        raise ValueError(f"'{MENAGERIE}{name}': {exc} (offline: MENAGERIE_ROOT=<a Menagerie "
                         'clone>)') from None
