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
One robot in the PyBullet world, with the API of the reference's Gazebo model.

PyBullet traps handled here:
* every joint starts with a velocity motor holding it still: they are switched off (zero force) so
  that torque control works;
* torque commands are forgotten after each step: the command is re-applied before every step;
* the "applied" torque PyBullet reports in torque mode is zero: the measured effort is the command
  applied;
* base position/velocity are those of the base's centre of mass: they are moved to the URDF link
  frame;
* the URDF's inertias are used (PyBullet recomputes them from collision shapes unless told
  otherwise, and gives 1 kg to links without ``<inertial>``, which URDF and Pinocchio take as
  massless), and PyBullet's default link damping is removed, so the simulated dynamics match the
  controller's model;
* PyBullet orders joints as the URDF file lists them, which is not Pinocchio's order (it sorts
  sibling subtrees by joint name): every array method takes optional joint ``names`` and then
  works in their order; :meth:`SimModel.joint_map` precomputes the map for a control loop.

Joints given to :meth:`SimModel.set_joint_position_servo` are held by PyBullet's position motor
(a gripper's own driver, say) and take no torque commands. Friction: :meth:`SimModel.set_friction`;
contacts: :meth:`SimModel.get_contacts` (see :mod:`orca_ros.sim.contacts`).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import pybullet

from .contacts import ContactsMixin
from .joint_map import JointMap
from ..robot.mjcf import is_mjcf


def _rot(quat_xyzw) -> np.ndarray:
    return np.array(pybullet.getMatrixFromQuaternion(quat_xyzw)).reshape(3, 3)


class SimModel(ContactsMixin):
    def __init__(self, server, urdf_path, position, orientation, name, fixed_base):
        self.server = server
        c = self.client = server.client
        self.fixed_base = bool(fixed_base)
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE
        with open(urdf_path) as fh:
            if is_mjcf(fh.read()):
                raise ValueError(f"'{urdf_path}' is MJCF: this world reads URDF (an MJCF robot "
                                 'runs on MuJoCo: mujoco_bridge)')
        self.body = c.loadURDF(
            urdf_path,
            basePosition=list(position),
            baseOrientation=list(orientation),
            useFixedBase=self.fixed_base,
            flags=flags,
        )
        self.name = name or c.getBodyInfo(self.body)[1].decode()
        self.urdf_path = urdf_path
        self._joint_ids, self._joint_names, self._effort = [], [], []
        for j in range(c.getNumJoints(self.body)):
            info = c.getJointInfo(self.body, j)
            if info[2] in (pybullet.JOINT_REVOLUTE, pybullet.JOINT_PRISMATIC):
                self._joint_ids.append(j)
                self._joint_names.append(info[1].decode())
                self._effort.append(info[10])
        self.ndof = len(self._joint_ids)
        for link in range(-1, c.getNumJoints(self.body)):
            c.changeDynamics(
                self.body, link, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0
            )
        self._massless_links_as_in_the_urdf(urdf_path)
        c.setJointMotorControlArray(
            self.body, self._joint_ids, pybullet.VELOCITY_CONTROL, forces=[0.0] * self.ndof
        )
        dyn = c.getDynamicsInfo(self.body, -1)
        self._base_com_pos = np.array(dyn[3])  # inertial frame in the link frame
        self._base_com_orn = np.array(dyn[4])
        self._cmd = np.zeros(self.ndof)
        self._gravity_torques = np.zeros(self.ndof)
        self._applied = np.zeros(self.ndof)
        self._brakes = False
        self._servo = np.zeros(self.ndof, dtype=bool)  # joints held by the position motor
        self._servo_target = np.zeros(self.ndof)
        self._callbacks: list[Callable[[int, float, float], None]] = []
        self._q = np.zeros(self.ndof)
        self._v = np.zeros(self.ndof)
        self._read_joints()

    def _massless_links_as_in_the_urdf(self, urdf_path) -> None:
        """
        Links without ``<inertial>`` are massless in URDF (and in Pinocchio); PyBullet gives 1 kg.

        Only links on a fixed joint are made massless (a massless link on a moving joint would
        make the joint's inertia zero).
        """
        import xml.etree.ElementTree as ET  # noqa: PLC0415

        try:
            root = ET.parse(urdf_path).getroot()
        except (ET.ParseError, OSError):
            return
        bare = {ln.get('name') for ln in root.findall('link') if ln.find('inertial') is None}
        c = self.client
        for j in range(c.getNumJoints(self.body)):
            info = c.getJointInfo(self.body, j)
            if info[12].decode() in bare and info[2] == pybullet.JOINT_FIXED:
                c.changeDynamics(self.body, j, mass=0.0, localInertiaDiagonal=[0.0, 0.0, 0.0])

    # -------------------------------------------------------------- names and configuration
    def get_name(self) -> str:
        return self.name

    def get_joint_names(self) -> list[str]:
        return list(self._joint_names)

    def get_nr_of_degrees_of_freedom(self) -> int:
        return self.ndof

    def get_joint_effort_limits(self) -> np.ndarray:
        """Return the URDF effort limits in this model's order (0: none given)."""
        return np.array(self._effort, dtype=float)

    def joint_map(self, names) -> JointMap:
        """Map between arrays ordered like ``names`` and this model's (PyBullet's) order."""
        return JointMap(self._joint_names, names, self.name)

    def _indices(self, names):
        return self.joint_map(names).sim_index

    def set_model_configuration(self, joint_names, joint_positions) -> None:
        """Teleport the named joints to the given positions (zero velocity)."""
        vals = np.asarray(joint_positions, dtype=float).reshape(-1)
        if len(joint_names) != vals.size:
            raise ValueError(f'{len(joint_names)} joint names but {vals.size} positions')
        for k, val in zip(self._indices(joint_names), vals):
            self.client.resetJointState(self.body, self._joint_ids[k], float(val), 0.0)
        self._read_joints()

    def set_base_pose(self, position, orientation_xyzw=(0, 0, 0, 1)) -> None:
        """Teleport the base (URDF link frame) for floating-base models."""
        R = _rot(orientation_xyzw)
        com = np.asarray(position, dtype=float) + R @ self._base_com_pos
        _, com_orn = pybullet.multiplyTransforms(
            [0, 0, 0], orientation_xyzw, [0, 0, 0], self._base_com_orn
        )
        self.client.resetBasePositionAndOrientation(self.body, com.tolist(), com_orn)

    def execute_after_world_update(self, cb: Callable[[int, float, float], None]) -> None:
        self._callbacks.append(cb)

    # -------------------------------------------------------------- commands
    def set_joint_torque_command(self, torques, names=None) -> None:
        """
        Torques for the next steps: all joints in this model's order, or the named ones.

        With ``names`` (or a :class:`JointMap`), only those joints' commands change.
        """
        tau = np.asarray(torques, dtype=float).reshape(-1)
        idx = self._selection(names)
        n = self.ndof if idx is None else idx.size
        if tau.shape != (n,):
            raise ValueError(
                f"model '{self.name}': torque command needs {n} values, got {tau.size}"
            )
        if not np.all(np.isfinite(tau)):
            raise ValueError(f"model '{self.name}': torque command contains NaN/inf")
        if idx is None:
            self._cmd[:] = tau
        else:
            self._cmd[idx] = tau

    def _selection(self, names):
        if names is None:
            return None
        if isinstance(names, JointMap):
            if names.sim_names != self._joint_names:
                raise ValueError(f"that joint map was not made for model '{self.name}'")
            return names.sim_index
        return self._indices(names)

    def set_joint_position_servo(self, names, positions, max_forces=None) -> None:
        """
        Hold the named joints at ``positions`` with PyBullet's position motor.

        For joints another controller drives (a gripper's fingers): they take no torque
        commands until :meth:`release_joint_position_servo`. ``max_forces`` default to the URDF
        effort limits.
        """
        idx = self._indices(names)
        x = np.asarray(positions, dtype=float).reshape(-1)
        if x.size != idx.size or not np.all(np.isfinite(x)):
            raise ValueError(f'{idx.size} finite positions needed for {list(names)}, got {x}')
        self._servo[idx] = True
        self._servo_target[idx] = x
        f = (
            np.array([self._effort[k] if self._effort[k] > 0 else 1e3 for k in idx])
            if max_forces is None
            else np.broadcast_to(np.asarray(max_forces, dtype=float), idx.shape)
        )
        self.client.setJointMotorControlArray(
            self.body,
            [self._joint_ids[k] for k in idx],
            pybullet.POSITION_CONTROL,
            targetPositions=x.tolist(),
            forces=f.tolist(),
        )

    def release_joint_position_servo(self, names) -> None:
        """Back to torque control for the named joints (motor off, zero command)."""
        idx = self._indices(names)
        self._servo[idx] = False
        self._cmd[idx] = 0.0
        self.client.setJointMotorControlArray(
            self.body,
            [self._joint_ids[k] for k in idx],
            pybullet.VELOCITY_CONTROL,
            forces=[0.0] * idx.size,
        )

    def get_servoed_joint_names(self) -> list[str]:
        return [n for n, s in zip(self._joint_names, self._servo) if s]

    def set_joint_gravity_torques(self, torques) -> None:
        """Torques added to every command, as drives with built-in gravity compensation would."""
        g = np.asarray(torques, dtype=float).reshape(-1)
        if g.shape != (self.ndof,) or not np.all(np.isfinite(g)):
            raise ValueError(
                f"model '{self.name}': gravity torques need {self.ndof} finite values"
            )
        self._gravity_torques[:] = g

    def set_brakes(self, on: bool = True) -> None:
        """
        Brakes hold the joints (velocity servo to zero with the joints' effort limits).

        Commands ignored.
        """
        self._brakes = bool(on)
        if not on:
            self.client.setJointMotorControlArray(
                self.body, self._joint_ids, pybullet.VELOCITY_CONTROL, forces=[0.0] * self.ndof
            )

    def apply_commands(self) -> None:
        """Send this step's commands to the simulator (the server calls it before each step)."""
        if self._brakes:
            forces = [e if e > 0 else 1e3 for e in self._effort]
            self.client.setJointMotorControlArray(
                self.body,
                self._joint_ids,
                pybullet.VELOCITY_CONTROL,
                targetVelocities=[0.0] * self.ndof,
                forces=forces,
            )
            self._applied[:] = 0.0
            return
        np.add(self._cmd, self._gravity_torques, out=self._applied)
        if self._servo.any():
            self._applied[self._servo] = 0.0
            torque = np.flatnonzero(~self._servo)
            self.client.setJointMotorControlArray(
                self.body,
                [self._joint_ids[k] for k in torque],
                pybullet.TORQUE_CONTROL,
                forces=self._applied[torque].tolist(),
            )
            return
        self.client.setJointMotorControlArray(
            self.body, self._joint_ids, pybullet.TORQUE_CONTROL, forces=self._applied.tolist()
        )

    def _read_joints(self) -> None:
        states = self.client.getJointStates(self.body, self._joint_ids)
        for k, s in enumerate(states):
            self._q[k] = s[0]
            self._v[k] = s[1]

    def after_step(self, n: int, t: float, dt: float) -> None:
        """Read the joints after step ``n`` (time ``t``) and call this model's callbacks."""
        self._read_joints()
        for cb in self._callbacks:
            cb(n, t, dt)

    # -------------------------------------------------------------- measurements
    def _pick(self, values: np.ndarray, names) -> np.ndarray:
        idx = self._selection(names)
        return values.copy() if idx is None else values[idx]

    def get_joint_positions(self, names=None) -> np.ndarray:
        """Joint positions in this model's order, or in the order of ``names``."""
        return self._pick(self._q, names)

    def get_joint_velocities(self, names=None) -> np.ndarray:
        return self._pick(self._v, names)

    def get_joint_measured_torques(self, names=None) -> np.ndarray:
        """
        Return the torque the drives applied during the last step.

        The command plus the emulated gravity compensation (zero for servoed joints, whose motor
        force PyBullet does not report in torque terms).
        """
        return self._pick(self._applied, names)

    def get_joint_external_torques(self) -> np.ndarray:
        """Not measured by this simulator: zeros (no joint torque sensors are emulated)."""
        return np.zeros(self.ndof)

    def get_world_to_base_transform(self) -> np.ndarray:
        """4x4 pose of the URDF base link frame in the world."""
        com, orn = self.client.getBasePositionAndOrientation(self.body)
        inv_pos, inv_orn = pybullet.invertTransform(
            self._base_com_pos.tolist(), self._base_com_orn.tolist()
        )
        pos, orn_link = pybullet.multiplyTransforms(com, orn, inv_pos, inv_orn)
        T = np.eye(4)
        T[:3, :3] = _rot(orn_link)
        T[:3, 3] = pos
        return T

    def get_base_velocity(self) -> np.ndarray:
        """Twist of the base link frame origin, world axes: [linear, angular]."""
        lin, ang = self.client.getBaseVelocity(self.body)
        lin, ang = np.array(lin), np.array(ang)
        T = self.get_world_to_base_transform()
        com, _ = self.client.getBasePositionAndOrientation(self.body)
        r = T[:3, 3] - np.array(com)  # from the centre of mass to the link origin
        return np.concatenate((lin + np.cross(ang, r), ang))

    def _link(self, link_name: str) -> int:
        if not hasattr(self, '_link_index'):
            self._link_index = {
                self.client.getJointInfo(self.body, j)[12].decode(): j
                for j in range(self.client.getNumJoints(self.body))
            }
            self._link_index[self.client.getBodyInfo(self.body)[0].decode()] = -1
        if link_name not in self._link_index:
            raise ValueError(f"model '{self.name}' has no link '{link_name}'")
        return self._link_index[link_name]

    def has_link(self, link_name: str) -> bool:
        """Tell whether the robot has a link named so (its base link included)."""
        try:
            self._link(link_name)
        except ValueError:
            return False
        return True

    def get_link_position(self, link_name: str) -> np.ndarray:
        """World position of a link frame's origin (URDF link frame, not its centre of mass)."""
        return np.array(
            self.client.getLinkState(
                self.body, self._link(link_name), computeForwardKinematics=True
            )[4]
        )

    def get_link_velocity(self, link_name: str):
        """
        (linear, angular) world velocity of a link.

        The linear one at the link's centre of mass.
        """
        s = self.client.getLinkState(self.body, self._link(link_name), computeLinkVelocity=True)
        return np.array(s[6]), np.array(s[7])

    def get_gravity(self) -> np.ndarray:
        return self.server.gravity.copy()
