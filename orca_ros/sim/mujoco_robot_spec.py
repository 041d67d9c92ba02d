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
A URDF or MJCF robot as a MuJoCo model specification (``mujoco.MjSpec``), ready to attach.

MuJoCo's URDF importer is made to give the robot the controller's model (Pinocchio's, from the
same file):

* ``package://`` and relative mesh names resolved to absolute paths as for PyBullet
  (:func:`~orca_ros.robot.urdf_text.resolve_package_uris`): MuJoCo knows no packages;
* every link stays a body (``fusestatic`` off): frames on fixed joints (a tool flange, a foot)
  are looked up by name as in the URDF;
* links without ``<inertial>`` on fixed joints (or the root) are massless, as URDF and Pinocchio
  read them (MuJoCo would give them the mass of their collision shapes at 1000 kg/m^3);
  degenerate inertias (Go1's dummy root: 1e-6 kg, a singular tensor) are bounded and balanced
  (``boundinertia``, ``balanceinertia``) instead of refusing the file;
* visual geometry dropped; the robot's collision shapes do not touch each other (PyBullet's
  default, without self-collision) but touch the ground and other robots: ``contype`` and
  ``conaffinity`` bits per robot;
* an MJCF file is MuJoCo's own: read as it is but for its actuators (removed, see
  :func:`_mjcf_spec`) and its placement;
* a floating base gets a free joint on the root link: ``qpos`` = (x, y, z, qw, qx, qy, qz) of
  the URDF base link frame, ``qvel`` = (linear velocity in world axes, angular in the base frame);
* one position actuator per joint, inert (zero gains) until a joint is servoed.
"""

from __future__ import annotations

from dataclasses import dataclass
import xml.etree.ElementTree as ET

import mujoco

from ..robot.mjcf import is_mjcf
from ..robot.urdf_text import resolve_package_uris

#: contype / conaffinity are int32 bit masks: bit 0 the ground's, bits 1-29 the robots' (one
#: each), bit 30 the obstacles'
ALL_BITS = 0x7FFFFFFF
OBSTACLE_BIT = 1 << 30
_MOVING = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))


@dataclass
class RobotSpec:
    """A robot's specification and the names the simulation addresses it by."""

    spec: mujoco.MjSpec
    joints: list  # the moving joints, in the URDF file's order (as PyBullet numbers them)
    links: list  # every link (body)
    base: str  # the root link


def servo_name(joint: str) -> str:
    """Name of the position actuator of ``joint``."""
    return f'servo_{joint}'


def robot_spec(urdf_path: str, position, orientation_xyzw, fixed_base: bool, collision_bit: int,
               package_dirs=None) -> RobotSpec:
    """
    Parse ``urdf_path`` into a specification placed at ``position`` / ``orientation_xyzw``.

    ``collision_bit``: this robot's contact bit (1 << k, 1 <= k <= 29; see ``ALL_BITS``). Raises
    ``ValueError`` naming the file when MuJoCo cannot read it.
    """
    with open(urdf_path) as fh:
        text = fh.read()
    if is_mjcf(text):
        spec, base = _mjcf_spec(urdf_path, fixed_base)
    else:
        text = resolve_package_uris(text, urdf_path, package_dirs)
        try:
            root = ET.fromstring(text)
            spec = mujoco.MjSpec.from_string(text)
        except (ET.ParseError, ValueError) as exc:
            raise ValueError(f"MuJoCo cannot read '{urdf_path}': {exc}") from exc
        spec.compiler.fusestatic = False
        spec.compiler.boundinertia = 1e-9
        spec.compiler.balanceinertia = True
        _massless_as_in_the_urdf(spec, root, fixed_base)
        base = spec.worldbody.bodies[0]
        if not fixed_base:
            base.add_freejoint(name='root')
    spec.compiler.discardvisual = True
    x, y, z, w = (float(c) for c in orientation_xyzw)
    base.pos, base.quat = [float(c) for c in position], [w, x, y, z]
    for g in spec.geoms:
        if g.contype or g.conaffinity:
            g.contype, g.conaffinity = collision_bit, ALL_BITS & ~collision_bit
    joints = [j.name for j in spec.joints if int(j.type) in _MOVING]
    for name in joints:
        actuator = spec.add_actuator(name=servo_name(name), target=name,
                                     trntype=mujoco.mjtTrn.mjTRN_JOINT)
        actuator.set_to_position(kp=0.0)
    links = [b.name for b in spec.bodies if b.name != 'world']
    return RobotSpec(spec, joints, links, base.name)


def _mjcf_spec(path: str, fixed_base: bool):
    """
    Return (spec, root body) of the MJCF file ``path`` (its meshes found from its directory).

    The file's actuators are removed (the bridge drives the joints, as the hardware's drives
    would); its joints' damping, armature and friction stay (the simulated robot's physics, which
    Pinocchio's model has not). A floating base: the root body's ``freejoint`` or one added; a
    fixed base with one is refused, as the controller's model refuses it.
    """
    try:
        spec = mujoco.MjSpec.from_file(path)
    except ValueError as exc:
        raise ValueError(f"MuJoCo cannot read '{path}': {exc}") from exc
    for actuator in list(spec.actuators):
        spec.delete(actuator)
    base = spec.worldbody.bodies[0]
    free = [j for j in base.joints if int(j.type) == int(mujoco.mjtJoint.mjJNT_FREE)]
    if free and fixed_base:
        raise ValueError(f"MJCF '{path}': its root body has a free joint ('{free[0].name}'): "
                         'load it with a floating base')
    if free:
        free[0].name = 'root'
    elif not fixed_base:
        base.add_freejoint(name='root')
    return spec, base


def _massless_as_in_the_urdf(spec, root, fixed_base: bool) -> None:
    """
    Links without ``<inertial>`` on fixed joints get no mass (see the module).

    The root too on a fixed base; a floating root keeps what MuJoCo gives it (a moving body
    without mass is refused by MuJoCo).
    """
    children = {j.find('child').get('link'): j.get('type') for j in root.findall('joint')}
    for link in root.findall('link'):
        name = link.get('name')
        fixed = children.get(name, 'fixed' if fixed_base else 'free') == 'fixed'
        if link.find('inertial') is None and fixed:
            body = spec.body(name)
            body.explicitinertial = True
            body.mass, body.inertia = 0.0, [0.0, 0.0, 0.0]
