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

import numpy as np
import pinocchio as pin

from . import state_input
from .dynamics_api import DynamicsApiMixin
from .frame_api import FrameApiMixin
from .joint_locking import LockedJoints
from .model_files import model_from_file, model_from_urdf_text
from .state_buffers import StateBuffers
from ..utils.logger import get_logger

_LOG = get_logger('robot')
_ARRAY, _F64 = np.ndarray, np.dtype(np.float64)
WORLD_FRAME = 'world'


class RobotModel(DynamicsApiMixin, FrameApiMixin):
    """
    Kinematic/dynamic model of a robot.

    Updated with :meth:`set_robot_state` every control cycle.
    """

    def __init__(self, name: str = ''):
        self.name = name
        self.model: pin.Model | None = None
        self.data: pin.Data | None = None
        # the current state, Pinocchio's Data of the cycle (state_buffers.py); made per model
        self.buffers: StateBuffers | None = None
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
        src = model_from_file(path, floating_base)
        self._locked = None
        self.urdf_path, self.urdf_xml, self.mjcf_path = src.urdf_path, src.urdf_xml, src.mjcf_path
        self._setup(src.model, floating_base)
        return True

    def load_model_from_string(self, urdf_xml: str, floating_base: bool = False) -> bool:
        """Load the robot from URDF text (MJCF: its file, :meth:`load_model_from_file`)."""
        model = model_from_urdf_text(urdf_xml, floating_base)
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
        self.floating_base = bool(floating_base)
        if not self.name:
            self.name = model.name
        first = 2 if floating_base else 1
        self._joint_ids = list(range(first, model.njoints))
        self._joint_names = [model.names[j] for j in self._joint_ids]
        self.nbase = 6 if floating_base else 0
        self.ndof = model.nv - self.nbase
        # the state's buffers (continuous joints are cos/sin pairs in Pinocchio's q); the stamp
        # goes on from the last model's: no cache keyed on a stamp takes the new state for old
        last = self.buffers
        self.buffers = buf = StateBuffers(model, self._joint_ids, self.ndof)
        if last is not None:
            buf.stamp = last.stamp + 1
        lower = np.full(self.ndof, -np.inf)
        upper = np.full(self.ndof, np.inf)
        for k, (iq, nq) in enumerate(buf.q_map):
            if nq == 1:
                lower[k], upper[k] = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
        lower[lower < -1e10] = -np.inf
        upper[upper > 1e10] = np.inf
        self._pos_limits = (lower, upper)
        self._vel_limits = np.array(model.velocityLimit[self.nbase:], dtype=float)
        self._trq_limits = np.array(model.effortLimit[self.nbase:], dtype=float)
        # the root link (with a floating base: the free-flyer's child link) is the default base
        # frame
        self._base_frame = None
        self.set_base_frame(self._first_body_frame() or WORLD_FRAME)
        self.set_gravity(np.array([0.0, 0.0, -9.81]))
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
    def set_gravity(self, gravity) -> None:
        self._require_model()
        g = np.asarray(gravity, dtype=float).reshape(-1)
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise ValueError(f'gravity must be a finite 3-vector, got {gravity!r}')
        self.model.gravity.linear = g
        buf = self.buffers
        buf.gravity[:] = g
        buf.stamp += 1

    def get_gravity(self) -> np.ndarray:
        return self.buffers.gravity.copy()

    # ------------------------------------------------------------------ state
    def set_robot_state(self, *args) -> None:
        """
        Set the robot's state: ``(q, v)`` for a fixed base.

        Or ``set_robot_state(world_H_base, q, base_twist_world, v, gravity)`` (also valid for a
        fixed base: the base transform/twist are then ignored and only the gravity is applied).
        """
        buf = self.buffers
        fast = None if buf is None else buf.state_kernel  # the common inputs, by kernel (made
        # by a compiled cycle)
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
        buf = self.buffers
        fast = None if buf is None else buf.state_kernel  # by kernel, inline: the common input
        # of every cycle (see StateKernel: exactly ndarray, float64 itself, the sizes; the
        # kernel checks the values)
        if (fast is not None and type(q) is _ARRAY and type(v) is _ARRAY and q.dtype is _F64
                and v.dtype is _F64 and fast.shapes is not None and q.shape == fast.shapes[0]
                and v.shape == fast.shapes[1] and not fast.take(q, v, fast.arrays)):
            if fast.nb:
                buf.base_from_q_pin = True
            buf.stamp += 1
            buf.initialized = True
            return
        self._require_model()
        state_input.set_configuration(self, q, v)

    def _checked(self, x, shape, what) -> np.ndarray:
        return state_input.checked(self, x, shape, what)

    def is_initialized(self) -> bool:
        return self.buffers is not None and self.buffers.initialized

    def update_terms(self) -> None:
        """
        Pinocchio's ``computeAllTerms`` for the current state into :attr:`data`, once per state.

        The mass matrix, nonlinear effects, joint placements, Jacobians and their velocities and
        drifts, the centre of mass: what the frame and dynamics getters read. RuntimeError
        before a state was given.
        """
        buf = self.buffers
        if buf is None or not buf.initialized:
            self._require_model()
            raise RuntimeError(
                f"robot '{self.name}' has no state yet: call set_robot_state() first"
            )
        if buf.terms_stamp != buf.stamp:
            pin.computeAllTerms(self.model, self.data, buf.q_pin, buf.v_pin)
            buf.terms_stamp = buf.stamp

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

    # ------------------------------------------------------------------ locked joints
    def lock_joints(self, names, positions=None, tolerance: float = 1e-4) -> None:
        """
        Weld the named joints at ``positions``: the model then has only the other joints.

        For joints another controller drives (a gripper's fingers): they stay in the model at
        the position :meth:`set_locked_joint_positions` last gave, and the controller never
        commands them. Call it before tasks and constraints are added (their sizes follow). An
        empty list restores the full model.
        """
        self._require_model()
        full = self._locked.full_model if self._locked is not None else self.model
        base_frame, gravity = self._base_frame, self.buffers.gravity.copy()
        if not list(names):
            self._locked = None
            self._setup(full, self.floating_base)
        else:
            locked = LockedJoints(full, names, tolerance)
            if positions is not None:
                locked.positions = locked.checked(positions)
            self._setup(locked.reduced_model(), self.floating_base)
            self._locked = locked
        if self.frame_exists(base_frame):
            self.set_base_frame(base_frame)
        self.set_gravity(gravity)

    def set_locked_joint_positions(self, positions) -> bool:
        """
        Measured positions of the locked joints (order of :meth:`get_locked_joint_names`).

        The model is welded again when one moved by more than the tolerance (True then); the
        state set with :meth:`set_robot_state` is kept.
        """
        locked = self._locked
        if locked is None:
            raise RuntimeError(f"robot '{self.name}' has no locked joints")
        x = locked.checked(positions)
        if not locked.moved(x):
            return False
        model = locked.reduced_model(x)
        buf = self.buffers  # the state stays (the same joints); the model's terms are new
        model.gravity.linear = buf.gravity
        self.model = model
        self.data = model.createData()
        self._gravity_data = model.createData()
        buf.com = buf.centroidal = None
        self.set_base_frame(self._base_frame)  # clears the frame cache
        buf.stamp += 1
        return True

    def get_full_model(self):
        """Return the model with every joint of the URDF (the locked ones too)."""
        return self.model if self._locked is None else self._locked.full_model

    def get_locked_joint_names(self) -> list[str]:
        return [] if self._locked is None else list(self._locked.names)

    def get_locked_joint_positions(self) -> np.ndarray:
        return np.zeros(0) if self._locked is None else self._locked.positions.copy()

    def get_locked_joint_position_limits(self):
        if self._locked is None:
            return np.zeros(0), np.zeros(0)
        return self._locked.lower.copy(), self._locked.upper.copy()

    # ------------------------------------------------------------------ state getters
    def get_joint_positions(self) -> np.ndarray:
        return self.buffers.q.copy()

    def get_joint_velocities(self) -> np.ndarray:
        return self.buffers.v.copy()

    def get_generalized_velocity(self) -> np.ndarray:
        """Return nu in Pinocchio's convention (a view, valid until the next state change)."""
        return self.buffers.v_pin

    def get_configuration(self) -> np.ndarray:
        """Return q in Pinocchio's convention (see :meth:`set_configuration`), a copy."""
        return self.buffers.q_pin.copy()

    def get_world_to_base_transform(self) -> np.ndarray:
        state_input.sync_base(self)
        return self.buffers.world_H_base.copy()

    def get_base_velocity(self) -> np.ndarray:
        state_input.sync_base(self)
        return self.buffers.base_twist_world.copy()

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
