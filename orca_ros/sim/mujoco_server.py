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
MuJoCo world standing in for the robot hardware: :class:`~orca_ros.sim.SimServer`'s contract.

The same methods with the same meaning as the PyBullet world, so that a loop written on one runs
on the other: a fixed time step, gravity, an optional ground plane, URDF robots inserted
(:class:`~orca_ros.sim.mujoco_model.MujocoModel`), ``step()`` / ``run()`` calling every model's
and every registered after-step callback with (iteration, time, dt).

Integration: ``implicitfast`` by default. Without velocity-dependent forces it is the same
semi-implicit Euler step as PyBullet's and as Pinocchio's ``aba`` followed by
``v += a dt; q += v dt``; with a servo's damping it stays stable where explicit Euler does not.
Contacts: elliptic friction cones with ``impratio`` 10 (MuJoCo's advice for legged robots: the
default pyramidal cones let standing feet creep), stiffer than MuJoCo's default
(``CONTACT_TIME``, ``CONTACT_IMPEDANCE``): a foot sinks hundredths of a millimetre, as on PyBullet,
not a millimetre. Joint limits are MuJoCo's soft constraints
(``solref`` 0.02 s): a joint driven into its stop passes it further than PyBullet's.

Each inserted robot recompiles the world (``MjSpec.recompile`` keeps the state of the robots
already in it). After ``mj_step`` MuJoCo's positions of bodies are those of the state before the
step: the kinematics are computed again, so that what a model reads after a step is of its new
state; contacts stay those the step was computed with.

When the accelerations are not finite (a torque far beyond what a joint's inertia takes in one
step), MuJoCo resets the state to the model's rest pose, warns and goes on: counted here in
``resets`` (``last_reset``: when) for a caller to say so; MuJoCo's warnings go to the log.
"""

from __future__ import annotations

from typing import Callable

import mujoco
import numpy as np

from .contacts import friction_values
from .mujoco_base_hold import MujocoBaseHold
from .mujoco_contacts import set_geom_friction
from .mujoco_model import MujocoModel
from .mujoco_obstacles import MujocoObstacles
from .mujoco_robot_spec import ALL_BITS, OBSTACLE_BIT
from .stepping import run_world
from ..utils.logger import get_logger

INTEGRATORS = {'euler': mujoco.mjtIntegrator.mjINT_EULER,
               'implicitfast': mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
               'implicit': mujoco.mjtIntegrator.mjINT_IMPLICIT,
               'rk4': mujoco.mjtIntegrator.mjINT_RK4}
GROUND = 'ground_plane'
_LOG = get_logger('mujoco')
_UNSTABLE = int(mujoco.mjtWarning.mjWARN_BADQACC)
#: contacts: time constant [s] (at least 2 steps) and impedance of MuJoCo's soft contacts. Its
#: defaults (20 ms; 0.9-0.95 over 1 mm) let Solo12's feet sink into the ground under its weight,
#: these a small fraction of that
CONTACT_TIME = 0.005
CONTACT_IMPEDANCE = [0.99, 0.999, 0.001, 0.5, 2.0]


class MujocoServer:
    def __init__(self, gui: bool = False, time_step: float = 0.001, gravity=(0.0, 0.0, -9.81),
                 ground_plane: bool = True, integrator: str = 'implicitfast'):
        if not time_step > 0.0:
            raise ValueError(f'time step must be > 0 s, got {time_step}')
        if integrator not in INTEGRATORS:
            raise ValueError(
                f"integrator must be one of {sorted(INTEGRATORS)}, got '{integrator}'")
        self.gui = bool(gui)
        self.time_step = float(time_step)
        self.spec = mujoco.MjSpec()
        self.spec.modelname = 'world'
        option = self.spec.option
        option.timestep = self.time_step
        option.integrator = INTEGRATORS[integrator]
        option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        option.impratio = 10.0
        option.enableflags |= mujoco.mjtEnableBit.mjENBL_OVERRIDE  # every contact's softness:
        option.o_solref = [max(CONTACT_TIME, 2.0 * self.time_step), 1.0]
        option.o_solimp = CONTACT_IMPEDANCE
        #: the root body id of what a contact with the ground touches (ContactPoint.other_body)
        self.plane_id = None
        if ground_plane:
            self.spec.worldbody.add_geom(name=GROUND, type=mujoco.mjtGeom.mjGEOM_PLANE,
                                         size=[0.0, 0.0, 1.0], contype=1,
                                         conaffinity=ALL_BITS & ~OBSTACLE_BIT)
            self.plane_id = 0
        self.model = self.spec.compile()
        self.data = mujoco.MjData(self.model)
        self.gravity = np.zeros(3)
        self.set_gravity(gravity)
        self.models: list[MujocoModel] = []
        self.iteration = 0
        self.sim_time = 0.0
        self._callbacks: list[Callable[[int, float, float], None]] = []
        self._viewer = None
        #: times MuJoCo found the accelerations not finite and reset the state, and the last's time
        self.resets, self.last_reset = 0, None
        if mujoco.get_mju_user_warning() is None:  # its warnings to our log, not to a file in
            mujoco.set_mju_user_warning(lambda text: _LOG.warning('MuJoCo: %s', text))  # the cwd
        #: named static obstacles (spheres, boxes, cylinders): add, move, remove, depth_into
        self.obstacles = MujocoObstacles(self)

    def set_gravity(self, gravity) -> None:
        self.gravity = np.asarray(gravity, dtype=float).reshape(3).copy()
        self.model.opt.gravity[:] = self.gravity

    def set_ground_friction(self, lateral: float, spinning=None, rolling=None) -> None:
        """Friction coefficients of the ground plane (MuJoCo takes the larger of two geoms')."""
        if self.plane_id is None:
            raise RuntimeError('this world has no ground plane')
        set_geom_friction(self.model, [self.model.geom(GROUND).id],
                          friction_values(lateral, spinning, rolling))

    def get_time(self) -> float:
        return self.sim_time

    def get_iteration(self) -> int:
        return self.iteration

    def insert_model_from_urdf_file(self, urdf_path: str, position=(0.0, 0.0, 0.0),
                                    orientation=(0.0, 0.0, 0.0, 1.0), name: str = '',
                                    fixed_base: bool = True, package_dirs=None) -> MujocoModel:
        """Load a URDF; orientation is a quaternion (x, y, z, w)."""
        bit = 1 << (1 + len(self.models) % 29)
        model = MujocoModel(self, urdf_path, position, orientation, name, fixed_base, bit,
                            package_dirs)
        self.models.append(model)
        self.recompile()
        return model

    def hold_base(self, model):
        """Hold ``model``'s floating base where it is now (:class:`.MujocoBaseHold`)."""
        return MujocoBaseHold(self, model)

    def recompile(self) -> None:
        """Compile the world again after its specification changed (the state is kept)."""
        self.model, self.data = self.spec.recompile(self.model, self.data)
        self.model.opt.gravity[:] = self.gravity
        for m in self.models:
            m.bind()  # the addresses of the recompiled model; its run-time settings again
        mujoco.mj_forward(self.model, self.data)
        for m in self.models:
            m.read_joints()
        if self.gui:
            self._open_viewer()

    def _open_viewer(self) -> None:
        import mujoco.viewer  # noqa: PLC0415 - a display is needed only for the GUI

        if self._viewer is not None:
            self._viewer.close()
        self._viewer = mujoco.viewer.launch_passive(self.model, self.data)

    def execute_after_world_update(self, cb: Callable[[int, float, float], None]) -> None:
        self._callbacks.append(cb)

    def step(self, n: int = 1) -> None:
        dt = self.time_step
        m, d = self.model, self.data
        for _ in range(n):
            for model in self.models:
                model.apply_commands()
            mujoco.mj_step(m, d)
            if d.warning[_UNSTABLE].number:  # MuJoCo reset the state (to the model's rest pose)
                d.warning[_UNSTABLE].number = 0
                self.resets += 1
                self.last_reset = self.sim_time + dt
            mujoco.mj_kinematics(m, d)  # the bodies where the new state puts them
            mujoco.mj_comPos(m, d)
            mujoco.mj_comVel(m, d)
            self.iteration += 1
            self.sim_time = self.iteration * dt
            for model in self.models:
                model.after_step(self.iteration, self.sim_time, dt)
            for cb in self._callbacks:
                cb(self.iteration, self.sim_time, dt)
        if self._viewer is not None:
            self._viewer.sync()

    def run(self, duration: float | None = None, real_time: bool = False,
            should_stop: Callable[[], bool] | None = None) -> None:
        """Step for ``duration`` simulated seconds or until ``should_stop()`` (see run_world)."""
        run_world(self, duration, real_time, should_stop)

    def shutdown(self) -> None:
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.shutdown()
