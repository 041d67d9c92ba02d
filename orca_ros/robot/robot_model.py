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
Robot kinematics and dynamics on Pinocchio, for fixed-base and floating-base robots.

Conventions
-----------
* Joint order is Pinocchio's (depth-first over the URDF tree); :meth:`get_joint_names` gives it.
* Fixed base (default): the URDF root link is welded to the world, configuration = joint angles.
* Floating base (``floating_base=True``): a free-flyer root; the generalized velocity is [base
  twist in the *base* frame (linear, angular) -- Pinocchio's free-flyer convention, joint
  velocities]. The 5-argument :meth:`set_robot_state` takes the base twist in the *world* frame and
  converts it.
* Cartesian quantities are expressed in the *base frame* set by :meth:`set_base_frame` (default:
  the URDF root link; ``"world"`` for the inertial frame): 4x4 poses, 6xN Jacobians [linear;
  angular] of the frame origin's velocity in base-frame axes, and the matching bias acceleration
  J_dot * nu.
"""

from __future__ import annotations

import os

import numpy as np
import pinocchio as pin

from . import state_input
from .dynamics_api import DynamicsApiMixin
from .frame_api import FrameApiMixin
from .joint_locking import JointLockingMixin
from .mjcf import build_mjcf_model, is_mjcf
from ..utils.logger import get_logger

_LOG = get_logger('robot')
_ARRAY, _F64 = np.ndarray, np.dtype(np.float64)
WORLD_FRAME = 'world'


class RobotModel(DynamicsApiMixin, FrameApiMixin, JointLockingMixin):
    """
    Kinematic/dynamic model of a robot.

    Updated with :meth:`set_robot_state` every control cycle.
    """

    def __init__(self, name: str = ''):
        self.name = name
        self.model: pin.Model | None = None
        self.data: pin.Data | None = None
        self._initialized = False
        self._stamp = 0  # incremented at every state change; caches compare against it
        self._terms_stamp = -1
        self._gravity_stamp = -1
        self._frame_cache: dict[int, tuple] = {}
        self.urdf_path: str | None = None
        self.urdf_xml: str | None = None  # the description loaded (collision geometry reads it)
        self.mjcf_path: str | None = None  # the MJCF file loaded, if the robot came from one
        self._locked = None  # joint_locking.LockedJoints while joints are locked
        self.massless = False  # the kinematic formulation (set_massless)

    # ------------------------------------------------------------------ loading
    def load_model_from_file(self, path: str, floating_base: bool = False) -> bool:
        """
        Load the robot from a URDF or an MJCF file (told apart by the root element).

        MJCF (``<mujoco>``, :mod:`.mjcf`): Pinocchio's parser; bodies are frames, hinge and slide
        joints the joints, ``range`` the position limits, ``actuatorfrcrange`` and the actuators'
        ``forcerange`` the torque limits (MJCF has no velocity limits: infinite unless a
        configuration gives them). A ``freejoint`` on the root body is the floating base
        (``floating_base`` must then be True); ``floating_base`` without one adds it. Its
        collision geoms are the collision geometry. ValueError naming what the parser refused.
        """
        if not isinstance(path, (str, os.PathLike)) or not os.path.isfile(path):
            raise FileNotFoundError(f"robot model file not found: '{path}'")
        with open(path, 'r', encoding='utf-8') as fh:
            xml = fh.read()
        if is_mjcf(xml):
            self._locked = None
            model = build_mjcf_model(os.fspath(path), floating_base)
            self.urdf_path, self.urdf_xml, self.mjcf_path = None, None, os.fspath(path)
            self._setup(model, floating_base)
            return True
        self.urdf_path = os.fspath(path)
        return self.load_model_from_string(xml, floating_base)

    def load_model_from_string(self, urdf_xml: str, floating_base: bool = False) -> bool:
        """Load the robot from URDF text (MJCF: its file, :meth:`load_model_from_file`)."""
        if isinstance(urdf_xml, str) and is_mjcf(urdf_xml):
            raise ValueError('MJCF text: give its file (its meshes and includes are found from '
                             'its directory)')
        if not isinstance(urdf_xml, str) or '<robot' not in urdf_xml:
            raise ValueError('not a URDF description: no <robot> element in the given string')
        try:
            if floating_base:
                model = pin.buildModelFromXML(urdf_xml, pin.JointModelFreeFlyer())
            else:
                model = pin.buildModelFromXML(urdf_xml)
        except Exception as exc:  # pinocchio raises ValueError/RuntimeError with its own text
            raise ValueError(f'could not parse URDF: {exc}') from exc
        self._locked = None
        self.urdf_xml, self.mjcf_path = urdf_xml, None
        self._setup(model, floating_base)
        return True

    def _setup(self, model: pin.Model, floating_base: bool) -> None:
        if self.massless:
            model = pin.Model(model)  # the caller's keeps its inertias
            for i in range(len(model.inertias)):
                model.inertias[i] = pin.Inertia.Zero()
        self.model = model
        self.data = model.createData()
        # gravity is computed on its own Data: its RNEA pass would overwrite the
        # velocities/accelerations that computeAllTerms left in self.data for the frame quantities
        # of the same state
        self._gravity_data = model.createData()
        self._com = None
        self._centroidal = None
        self.floating_base = bool(floating_base)
        if not self.name:
            self.name = model.name
        first = 2 if floating_base else 1
        self._joint_ids = list(range(first, model.njoints))
        self._joint_names = [model.names[j] for j in self._joint_ids]
        self.nbase = 6 if floating_base else 0
        self.ndof = model.nv - self.nbase
        # mapping joint angles -> Pinocchio configuration (continuous joints are cos/sin pairs)
        self._q_simple = True
        self._q_map = []
        for j in self._joint_ids:
            jm = model.joints[j]
            if jm.nq == jm.nv == 1:
                self._q_map.append((jm.idx_q, 1))
            elif jm.nq == 2 and jm.nv == 1:
                self._q_map.append((jm.idx_q, 2))
                self._q_simple = False
            else:
                raise ValueError(
                    f"joint '{model.names[j]}' of type {jm.shortname()} is not supported "
                    '(only 1-DoF revolute/prismatic/continuous joints)'
                )
        lower = np.full(self.ndof, -np.inf)
        upper = np.full(self.ndof, np.inf)
        for k, (iq, nq) in enumerate(self._q_map):
            if nq == 1:
                lower[k], upper[k] = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
        lower[lower < -1e10] = -np.inf
        upper[upper > 1e10] = np.inf
        self._pos_limits = (lower, upper)
        self._vel_limits = np.array(model.velocityLimit[self.nbase:], dtype=float)
        self._trq_limits = np.array(model.effortLimit[self.nbase:], dtype=float)
        # the fast state input a compiled cycle may give (robot/state_input.py); None: Python's
        self._state_kernel = None
        self._q_pin = pin.neutral(model)
        self._v_pin = np.zeros(model.nv)
        self._q = np.zeros(self.ndof)
        self._v = np.zeros(self.ndof)
        self._world_H_base = np.eye(4)
        self._base_twist_world = np.zeros(6)
        self._base_from_q_pin = (
            False  # set_configuration: world_H_base / twist derived from q, v on demand
        )
        # the root link (with a floating base: the free-flyer's child link) is the default base
        # frame
        self._base_frame = None
        self.set_base_frame(self._first_body_frame() or WORLD_FRAME)
        self.set_gravity(np.array([0.0, 0.0, -9.81]))
        self._initialized = False
        self._frame_cache.clear()

    def set_massless(self) -> None:
        """
        Drop the model's inertias: the kinematic formulation.

        The mass matrix, gravity and Coriolis terms are zero from then on (joint locking keeps
        them so): a controller on this model computes joint accelerations only, its torques zero.
        For a robot whose dynamics model is unknown or whose torques cannot be commanded, driven
        by position or velocity (mc_rtc's kinematic mode, PlaCo's kinematics solver). Rows that
        need the dynamics (torques, contact forces, the centre of mass) mean nothing here.
        Call it after loading, before anything else is set (the model is set up again).
        """
        self._require_model()
        self.massless = True
        self._setup(self.model, self.floating_base)

    def _first_body_frame(self) -> str | None:
        for f in self.model.frames:
            if f.type == pin.FrameType.BODY:
                return f.name
        return None

    def _require_model(self) -> None:
        if self.model is None:
            raise RuntimeError(
                'no model loaded: call load_model_from_file() or load_model_from_string() first'
            )

    # ------------------------------------------------------------------ configuration
    def set_base_frame(self, frame: str) -> None:
        """
        Frame in which every pose.

        Jacobian and acceleration is expressed ('world' = inertial frame).
        """
        self._require_model()
        fid = self.get_frame_id(frame)
        self._base_frame = frame
        self._base_fid = fid
        # a frame rigidly attached to the world never moves: its transform is constant
        self._base_static = (not self.floating_base) and (
            fid < 0 or self.model.frames[fid].parentJoint == 0
        )
        self._base_is_world = fid < 0 or (
            self._base_static and self._frame_world_pose_static(fid) is None
        )
        self._base_static_T = (
            None
            if self._base_is_world
            else (self._frame_world_pose_static(fid) if self._base_static else None)
        )
        self._frame_cache.clear()

    def _frame_world_pose_static(self, fid: int):
        """
        World pose of a frame attached to the universe joint.

        Or None when it is the identity.
        """
        T = self.model.frames[fid].placement.homogeneous
        return None if np.allclose(T, np.eye(4)) else T

    def get_base_frame(self) -> str:
        return self._base_frame

    def set_gravity(self, gravity) -> None:
        self._require_model()
        g = np.asarray(gravity, dtype=float).reshape(-1)
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise ValueError(f'gravity must be a finite 3-vector, got {gravity!r}')
        self.model.gravity.linear = g
        self._gravity = g.copy()
        self._stamp += 1

    def get_gravity(self) -> np.ndarray:
        return self._gravity.copy()

    # ------------------------------------------------------------------ state
    def set_robot_state(self, *args) -> None:
        """
        Set the robot's state: ``(q, v)`` for a fixed base.

        Or ``set_robot_state(world_H_base, q, base_twist_world, v, gravity)`` (also valid for a
        fixed base: the base transform/twist are then ignored and only the gravity is applied).
        """
        fast = self._state_kernel  # the common inputs, by kernel (made by a compiled cycle)
        if fast is not None and (fast.joint_state(*args) if len(args) == 2 else
                                 len(args) == 5 and fast.full_state(*args)):
            return
        self._require_model()
        state_input.set_joint_and_base_state(self, args)

    def set_configuration(self, q, v) -> None:
        """
        State in Pinocchio's convention (what TSID and Pinocchio users hold).

        ``q`` of size nq (floating base: position, unit quaternion x y z w, then the joints), ``v``
        of size nv (floating base: the base twist in the base frame, then the joints).
        """
        fast = self._state_kernel  # by kernel, inline: the common input of every cycle (see
        # StateKernel: exactly ndarray, float64 itself, the sizes; the kernel checks the values)
        if (fast is not None and type(q) is _ARRAY and type(v) is _ARRAY and q.dtype is _F64
                and v.dtype is _F64 and fast.shapes is not None and q.shape == fast.shapes[0]
                and v.shape == fast.shapes[1] and not fast.take(q, v, fast.arrays)):
            if fast.nb:
                self._base_from_q_pin = True
            self._stamp += 1
            self._initialized = True
            return
        self._require_model()
        state_input.set_configuration(self, q, v)

    def _checked(self, x, shape, what) -> np.ndarray:
        return state_input.checked(self, x, shape, what)

    def is_initialized(self) -> bool:
        return self._initialized

    def _update_terms(self) -> None:
        if not self._initialized:
            self._require_model()
            raise RuntimeError(
                f"robot '{self.name}' has no state yet: call set_robot_state() first"
            )
        if self._terms_stamp != self._stamp:
            pin.computeAllTerms(self.model, self.data, self._q_pin, self._v_pin)
            self._terms_stamp = self._stamp

    # ------------------------------------------------------------------ sizes and names
    def get_nr_of_degrees_of_freedom(self) -> int:
        self._require_model()
        return self.ndof

    def get_configuration_space_dimension(self) -> int:
        """Size of the generalized velocity: ndof (+6 with a floating base)."""
        self._require_model()
        return self.model.nv

    def is_floating_base(self) -> bool:
        return self.floating_base

    def get_joint_names(self) -> list[str]:
        return list(self._joint_names)

    def get_frame_names(self) -> list[str]:
        return [f.name for f in self.model.frames]

    def frame_exists(self, name: str) -> bool:
        return name == WORLD_FRAME or (self.model is not None and self.model.existFrame(name))

    def get_frame_id(self, name: str) -> int:
        """
        Pinocchio frame id of a link/joint frame; -1 for 'world'.

        Raises on unknown names.
        """
        self._require_model()
        if name == WORLD_FRAME:
            return -1
        if not isinstance(name, str) or not self.model.existFrame(name):
            known = sorted({f.name for f in self.model.frames if f.type == pin.FrameType.BODY})
            raise ValueError(
                f"unknown frame '{name}' in robot '{self.name}'; known links: {known}"
            )
        return self.model.getFrameId(name)

    # ------------------------------------------------------------------ limits from the URDF
    def get_joint_position_limits(self):
        return self._pos_limits[0].copy(), self._pos_limits[1].copy()

    def get_joint_velocity_limits(self) -> np.ndarray:
        return self._vel_limits.copy()

    def get_joint_torque_limits(self) -> np.ndarray:
        return self._trq_limits.copy()

    # ------------------------------------------------------------------ state getters
    def get_joint_positions(self) -> np.ndarray:
        return self._q.copy()

    def get_joint_velocities(self) -> np.ndarray:
        return self._v.copy()

    def get_generalized_velocity(self) -> np.ndarray:
        """Return nu in Pinocchio's convention (a view, valid until the next state change)."""
        return self._v_pin

    def get_configuration(self) -> np.ndarray:
        """Return q in Pinocchio's convention (see :meth:`set_configuration`), a copy."""
        return self._q_pin.copy()

    def get_world_to_base_transform(self) -> np.ndarray:
        state_input.sync_base(self)
        return self._world_H_base.copy()

    def get_base_velocity(self) -> np.ndarray:
        state_input.sync_base(self)
        return self._base_twist_world.copy()

    def print(self) -> None:  # noqa: A003 (ORCA API name)
        lo, hi = self._pos_limits
        lines = [
            f"RobotModel '{self.name}' ({'floating' if self.floating_base else 'fixed'} base, "
            f"{self.ndof} dof, base frame '{self._base_frame}')"
        ]
        for k, n in enumerate(self._joint_names):
            lines.append(
                f'  {n}: pos [{lo[k]:.3f}, {hi[k]:.3f}] vel {self._vel_limits[k]:.3f} '
                f'effort {self._trq_limits[k]:.1f}'
            )
        print('\n'.join(lines))
