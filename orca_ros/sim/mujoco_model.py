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
One URDF robot in the MuJoCo world: :class:`~orca_ros.sim.SimModel`'s contract on MuJoCo.

Joints are numbered as the URDF file lists them (as PyBullet numbers them), and every array
method takes optional joint ``names`` (or a :class:`~orca_ros.sim.JointMap`), as the PyBullet
model does. How the robot is built: :mod:`.mujoco_robot_spec`.

MuJoCo traps handled here:

* joint torques go through ``qfrc_applied``, which MuJoCo keeps from step to step: it is written
  before every step (the command, plus the emulated gravity compensation), and an external push
  is added for one step only;
* the URDF's joint damping and dry friction are zeroed, as the PyBullet model does: the
  simulated dynamics are the controller's model's;
* brakes are dry joint friction as large as the joints' effort limits with a hard constraint
  impedance (MuJoCo's default lets a loaded joint creep under its load);
* servoed joints (a gripper's own driver) are held by their position actuator, its gains set in
  the compiled model: a critically damped 50 Hz loop on the joint's own inertia by default. Run
  time settings of the compiled model are written again when the world is recompiled.
"""

from __future__ import annotations

from typing import Callable

import mujoco
import numpy as np

from .contacts import ContactPoint, friction_values
from .joint_map import JointMap
from .mujoco_contacts import robot_contacts, set_geom_friction
from .mujoco_robot_spec import robot_spec, servo_name

#: the servo's default bandwidth [Hz] (kp = m w^2, kv = 2 m w on the joint's own inertia m)
SERVO_HZ = 50.0
#: brakes: MuJoCo's constraint impedance while braked (its default 0.9 lets a joint creep)
BRAKE_IMPEDANCE = 0.9999


class MujocoModel:
    def __init__(self, server, urdf_path, position, orientation, name, fixed_base,
                 collision_bit: int, package_dirs=None):
        self.server = server
        self.fixed_base = bool(fixed_base)
        self.urdf_path = urdf_path
        built = robot_spec(urdf_path, position, orientation, self.fixed_base, collision_bit,
                           package_dirs)
        self.name = name or built.spec.modelname or built.base
        self.prefix = f'{self.name}/'
        self._joint_names, self._link_names = built.joints, built.links
        self._base_name = built.base
        server.spec.attach(built.spec, frame=server.spec.worldbody.add_frame(), prefix=self.prefix)
        n = self.ndof = len(self._joint_names)
        self._cmd, self._gravity_torques, self._applied = np.zeros(n), np.zeros(n), np.zeros(n)
        self._brakes = False
        self._servo = np.zeros(n, dtype=bool)
        self._servo_gains = np.zeros((n, 3))  # kp, kv, force bound of each servoed joint
        self._callbacks: list[Callable[[int, float, float], None]] = []
        self._q, self._v = np.zeros(n), np.zeros(n)
        self._push = None  # generalized forces of this step's external pushes

    # -------------------------------------------------------------- addresses in the world
    def bind(self) -> None:
        """Find this robot in the (re)compiled world; write its run-time settings again."""
        m, p = self.server.model, self.prefix
        joints = [m.joint(p + n).id for n in self._joint_names]
        self._qadr, self._dadr = m.jnt_qposadr[joints].copy(), m.jnt_dofadr[joints].copy()
        self._effort = np.array([m.jnt_actfrcrange[j, 1] if m.jnt_actfrclimited[j] else 0.0
                                 for j in joints])
        self._act = np.array([m.actuator(p + servo_name(n)).id for n in self._joint_names],
                             dtype=int)
        self._ctrl = m.actuator_ctrladr[self._act].copy()
        self._body = {n: m.body(p + n).id for n in self._link_names}
        self._names_of = {b: n for n, b in self._body.items()}
        self._base = self._body[self._base_name]
        self._root = None if self.fixed_base else m.joint(p + 'root')
        m.dof_damping[self._dadr] = 0.0
        m.dof_frictionloss[self._dadr] = 0.0
        self._solimp = m.dof_solimp[self._dadr, :2].copy()
        self._push = None
        self._write_servo_gains(np.arange(self.ndof))
        self.set_brakes(self._brakes)

    def read_joints(self) -> None:
        d = self.server.data
        self._q[:] = d.qpos[self._qadr]
        self._v[:] = d.qvel[self._dadr]

    # -------------------------------------------------------------- names and configuration
    def get_name(self) -> str:
        return self.name

    def get_joint_names(self) -> list[str]:
        return list(self._joint_names)

    def get_nr_of_degrees_of_freedom(self) -> int:
        return self.ndof

    def get_joint_effort_limits(self) -> np.ndarray:
        """Return the URDF effort limits in this model's order (0: none given)."""
        return self._effort.copy()

    def joint_map(self, names) -> JointMap:
        """Map between arrays ordered like ``names`` and this model's (the URDF file's) order."""
        return JointMap(self._joint_names, names, self.name)

    def _indices(self, names):
        return self.joint_map(names).sim_index

    def _selection(self, names):
        if names is None:
            return None
        if isinstance(names, JointMap):
            if names.sim_names != self._joint_names:
                raise ValueError(f"that joint map was not made for model '{self.name}'")
            return names.sim_index
        return self._indices(names)

    def set_model_configuration(self, joint_names, joint_positions) -> None:
        """Teleport the named joints to the given positions (zero velocity)."""
        vals = np.asarray(joint_positions, dtype=float).reshape(-1)
        if len(joint_names) != vals.size:
            raise ValueError(f'{len(joint_names)} joint names but {vals.size} positions')
        idx = self._indices(joint_names)
        d = self.server.data
        d.qpos[self._qadr[idx]] = vals
        d.qvel[self._dadr[idx]] = 0.0
        mujoco.mj_forward(self.server.model, d)
        self.read_joints()

    def set_base_pose(self, position, orientation_xyzw=(0, 0, 0, 1)) -> None:
        """Teleport the base (URDF link frame) for floating-base models (its velocity kept)."""
        if self._root is None:
            raise RuntimeError(f"model '{self.name}' has a fixed base")
        a = int(self._root.qposadr[0])
        x, y, z, w = (float(c) for c in orientation_xyzw)
        quat = np.array([w, x, y, z])
        d = self.server.data
        d.qpos[a:a + 3] = np.asarray(position, dtype=float).reshape(3)
        d.qpos[a + 3:a + 7] = quat / np.linalg.norm(quat)
        mujoco.mj_forward(self.server.model, d)

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
                f"model '{self.name}': torque command needs {n} values, got {tau.size}")
        if not np.all(np.isfinite(tau)):
            raise ValueError(f"model '{self.name}': torque command contains NaN/inf")
        if idx is None:
            self._cmd[:] = tau
        else:
            self._cmd[idx] = tau

    def set_joint_position_servo(self, names, positions, max_forces=None) -> None:
        """
        Hold the named joints at ``positions`` with their position actuators.

        For joints another controller drives (a gripper's fingers): they take no torque commands
        until :meth:`release_joint_position_servo`. ``max_forces`` default to the URDF effort
        limits (1000 where none is given).
        """
        idx = self._indices(names)
        x = np.asarray(positions, dtype=float).reshape(-1)
        if x.size != idx.size or not np.all(np.isfinite(x)):
            raise ValueError(f'{idx.size} finite positions needed for {list(names)}, got {x}')
        force = (np.where(self._effort[idx] > 0, self._effort[idx], 1e3) if max_forces is None
                 else np.broadcast_to(np.asarray(max_forces, dtype=float), idx.shape))
        m, d = self.server.model, self.server.data
        inertia = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, inertia)
        own = inertia[self._dadr[idx], self._dadr[idx]]
        w = 2.0 * np.pi * SERVO_HZ
        self._servo[idx] = True
        self._servo_gains[idx] = np.column_stack((own * w * w, 2.0 * own * w, force))
        self._write_servo_gains(idx)
        d.ctrl[self._ctrl[idx]] = x

    def release_joint_position_servo(self, names) -> None:
        """Back to torque control for the named joints (actuator off, zero command)."""
        idx = self._indices(names)
        self._servo[idx] = False
        self._cmd[idx] = 0.0
        self._servo_gains[idx] = 0.0
        self._write_servo_gains(idx)

    def _write_servo_gains(self, idx) -> None:
        m, a = self.server.model, self._act[idx]
        kp, kv, force = self._servo_gains[idx].T
        m.actuator_gainprm[a, 0] = kp
        m.actuator_biasprm[a, 1] = -kp
        m.actuator_biasprm[a, 2] = -kv
        m.actuator_forcelimited[a] = 1
        m.actuator_forcerange[a, 0] = -force
        m.actuator_forcerange[a, 1] = force

    def get_servoed_joint_names(self) -> list[str]:
        return [n for n, s in zip(self._joint_names, self._servo) if s]

    def set_joint_gravity_torques(self, torques) -> None:
        """Torques added to every command, as drives with built-in gravity compensation would."""
        g = np.asarray(torques, dtype=float).reshape(-1)
        if g.shape != (self.ndof,) or not np.all(np.isfinite(g)):
            raise ValueError(
                f"model '{self.name}': gravity torques need {self.ndof} finite values")
        self._gravity_torques[:] = g

    def set_brakes(self, on: bool = True) -> None:
        """Brake the joints (dry friction up to their effort limits); commands ignored."""
        self._brakes = bool(on)
        m = self.server.model
        if on:
            m.dof_frictionloss[self._dadr] = np.where(self._effort > 0, self._effort, 1e3)
            m.dof_solimp[self._dadr, :2] = BRAKE_IMPEDANCE
        else:
            m.dof_frictionloss[self._dadr] = 0.0
            m.dof_solimp[self._dadr, :2] = self._solimp

    def apply_commands(self) -> None:
        """Write this step's joint torques (the world calls it before each step)."""
        d = self.server.data
        if self._brakes:
            self._applied[:] = 0.0
        else:
            np.add(self._cmd, self._gravity_torques, out=self._applied)
            self._applied[self._servo] = 0.0
        d.qfrc_applied[self._dadr] = self._applied
        if self._push is not None:
            d.qfrc_applied += self._push

    def after_step(self, n: int, t: float, dt: float) -> None:
        """Read the new state; a push lasted its step (the world calls it after each step)."""
        if self._push is not None:
            self.server.data.qfrc_applied -= self._push
            self._push = None
        self.read_joints()
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
        """Return the torque applied during the last step (servoed joints: their actuator's)."""
        out = self._applied.copy()
        if self._servo.any():
            out[self._servo] = self.server.data.actuator_force[self._act[self._servo]]
        return self._pick(out, names)

    def get_joint_external_torques(self) -> np.ndarray:
        """Not measured by this simulator: zeros (no joint torque sensors are emulated)."""
        return np.zeros(self.ndof)

    def get_world_to_base_transform(self) -> np.ndarray:
        """4x4 pose of the URDF base link frame in the world."""
        d, T = self.server.data, np.eye(4)
        T[:3, :3] = d.xmat[self._base].reshape(3, 3)
        T[:3, 3] = d.xpos[self._base]
        return T

    def get_base_velocity(self) -> np.ndarray:
        """Twist of the base link frame origin, world axes: [linear, angular]."""
        twist = np.zeros(6)  # MuJoCo's order: angular, linear
        mujoco.mj_objectVelocity(self.server.model, self.server.data, mujoco.mjtObj.mjOBJ_XBODY,
                                 self._base, twist, 0)
        return np.concatenate((twist[3:], twist[:3]))

    def _link(self, link_name: str) -> int:
        if link_name not in self._body:
            raise ValueError(f"model '{self.name}' has no link '{link_name}'")
        return self._body[link_name]

    def has_link(self, link_name: str) -> bool:
        """Tell whether the robot has a link (a body) named so."""
        return link_name in self._body

    def get_link_position(self, link_name: str) -> np.ndarray:
        """World position of a link frame's origin (URDF link frame, not its centre of mass)."""
        return self.server.data.xpos[self._link(link_name)].copy()

    def get_link_velocity(self, link_name: str):
        """(linear, angular) world velocity of a link; the linear one at its centre of mass."""
        twist = np.zeros(6)
        mujoco.mj_objectVelocity(self.server.model, self.server.data, mujoco.mjtObj.mjOBJ_BODY,
                                 self._link(link_name), twist, 0)
        return twist[3:].copy(), twist[:3].copy()

    def get_gravity(self) -> np.ndarray:
        return self.server.gravity.copy()

    def get_base_inertia(self) -> tuple[float, np.ndarray]:
        """
        Return the whole robot's mass and its rotational inertia at the base (floating base).

        The inertia is the 3x3 block of the joint-space inertia matrix at the free joint's
        angular velocity (base axes, about the base link's origin): what a torque on the base
        turns with the joints locked.
        """
        if self._root is None:
            raise RuntimeError(f"model '{self.name}' has a fixed base")
        m, d = self.server.model, self.server.data
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        a = int(self._root.dofadr[0])
        mass = float(m.body_subtreemass[self._base])
        return mass, full[a + 3:a + 6, a + 3:a + 6].copy()

    def set_base_wrench(self, force, torque) -> None:
        """
        Apply ``force`` [N] and ``torque`` [Nm] (world axes) at the base link's origin, held.

        They stay until set again (zeros to stop): a crane holding the base
        (:mod:`.mujoco_base_hold`).
        """
        d = self.server.data
        f = np.asarray(force, dtype=float).reshape(3)
        arm = d.xpos[self._base] - d.xipos[self._base]  # from the centre of mass to the origin
        d.xfrc_applied[self._base, :3] = f
        torque = np.asarray(torque, dtype=float).reshape(3)
        d.xfrc_applied[self._base, 3:] = torque + np.cross(arm, f)

    # -------------------------------------------------------------- contacts
    def _geoms(self, bodies) -> list[int]:
        m = self.server.model
        return [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in bodies
                and (m.geom_contype[g] or m.geom_conaffinity[g])]

    def collision_geoms(self) -> list[tuple[str, int]]:
        """Return the (link name, MuJoCo geom id) of every collision shape of this robot."""
        m = self.server.model
        return [(self._names_of[int(m.geom_bodyid[g])], g)
                for g in self._geoms(set(self._body.values()))]

    def set_friction(self, lateral: float, spinning=None, rolling=None, links=None) -> None:
        """
        Coulomb friction coefficients of the named links (default: every link).

        MuJoCo combines two touching geoms' coefficients by taking the larger (the ground's are
        1 unless :meth:`MujocoServer.set_ground_friction` changes them).
        """
        bodies = set(self._body.values()) if links is None else {self._link(n) for n in links}
        set_geom_friction(self.server.model, self._geoms(bodies),
                          friction_values(lateral, spinning, rolling))

    def get_friction(self, link: str) -> dict:
        """Lateral, spinning and rolling friction coefficients of a link."""
        geoms = self._geoms({self._link(link)})
        if not geoms:
            raise ValueError(f"link '{link}' of model '{self.name}' has no collision geometry")
        f = self.server.model.geom_friction[geoms[0]]
        return {'lateral': float(f[0]), 'rolling': float(f[2]), 'spinning': float(f[1])}

    def get_contacts(self, links=None) -> list[ContactPoint]:
        """Contact points of the last step (of the named links only, when given)."""
        wanted = None if links is None else {self._link(n) for n in links}
        return robot_contacts(self.server.model, self.server.data, self._names_of, wanted)

    def get_contact_force(self, link: str) -> np.ndarray:
        """Total force the world exerts on ``link`` through its contacts (world frame) [N]."""
        f = np.zeros(3)
        for c in self.get_contacts([link]):
            f += c.force
        return f

    def apply_external_force(self, link: str, force, position=None) -> None:
        """
        Push ``link`` with a world-frame force [N] during the next step (a push, a tug).

        Applied at ``position`` (world frame) or at the link frame's origin; call it before every
        step of the push, as on PyBullet.
        """
        f = np.asarray(force, dtype=float).reshape(3)
        if not np.isfinite(f).all():
            raise ValueError(f'external force must be finite, got {force!r}')
        body = self._link(link)
        m, d = self.server.model, self.server.data
        at = d.xpos[body] if position is None else np.asarray(position, dtype=float).reshape(3)
        if self._push is None:
            self._push = np.zeros(m.nv)
        mujoco.mj_applyFT(m, d, f, np.zeros(3), at, body, self._push)
