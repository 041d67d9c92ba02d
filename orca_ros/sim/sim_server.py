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
PyBullet world standing in for the robot hardware (the reference's Gazebo server, on PyBullet).

DIRECT (headless) by default, GUI on request; fixed time step; gravity; optional ground plane;
``step()`` / ``run()`` call every model's after-step callbacks with (iteration, time, dt).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import pybullet
import pybullet_data
from pybullet_utils import bullet_client

from .base_hold import BaseHold
from .contacts import friction_values
from .pybullet_obstacles import PyBulletObstacles
from .sim_model import SimModel
from .stepping import run_world


class SimServer:
    def __init__(
        self,
        gui: bool = False,
        time_step: float = 0.001,
        gravity=(0.0, 0.0, -9.81),
        ground_plane: bool = True,
    ):
        if not time_step > 0.0:
            raise ValueError(f'time step must be > 0 s, got {time_step}')
        self.client = bullet_client.BulletClient(
            connection_mode=pybullet.GUI if gui else pybullet.DIRECT
        )
        self.gui = gui
        self.time_step = float(time_step)
        self.client.setAdditionalSearchPath(pybullet_data.getDataPath())
        self.client.setPhysicsEngineParameter(fixedTimeStep=self.time_step, numSubSteps=0)
        self.set_gravity(gravity)
        self.plane_id = self.client.loadURDF('plane.urdf') if ground_plane else None
        self.models: list[SimModel] = []
        self.iteration = 0
        self.sim_time = 0.0
        self._callbacks: list[Callable[[int, float, float], None]] = []
        #: resets of a blown-up state (MuJoCo's world counts them; PyBullet's never resets)
        self.resets, self.last_reset = 0, None
        #: named static obstacles (spheres, boxes, cylinders): add, move, remove, depth_into
        self.obstacles = PyBulletObstacles(self.client)

    def set_gravity(self, gravity) -> None:
        g = np.asarray(gravity, dtype=float).reshape(3)
        self.gravity = g
        self.client.setGravity(*g)

    def set_ground_friction(self, lateral: float, spinning=None, rolling=None) -> None:
        """Friction coefficients of the ground plane (PyBullet multiplies the two bodies')."""
        if self.plane_id is None:
            raise RuntimeError('this world has no ground plane')
        values = friction_values(lateral, spinning, rolling)
        self.client.changeDynamics(self.plane_id, -1, **values)

    def get_time(self) -> float:
        return self.sim_time

    def get_iteration(self) -> int:
        return self.iteration

    def insert_model_from_urdf_file(
        self,
        urdf_path: str,
        position=(0.0, 0.0, 0.0),
        orientation=(0.0, 0.0, 0.0, 1.0),
        name: str = '',
        fixed_base: bool = True,
    ) -> SimModel:
        """Load a URDF; orientation is a quaternion (x, y, z, w)."""
        model = SimModel(self, urdf_path, position, orientation, name, fixed_base)
        self.models.append(model)
        return model

    def hold_base(self, model) -> BaseHold:
        """Hold ``model``'s floating base where it is now (:class:`.BaseHold`)."""
        return BaseHold(self, model)

    def execute_after_world_update(self, cb: Callable[[int, float, float], None]) -> None:
        self._callbacks.append(cb)

    def step(self, n: int = 1) -> None:
        dt = self.time_step
        for _ in range(n):
            for m in self.models:
                m.apply_commands()
            self.client.stepSimulation()
            self.iteration += 1
            self.sim_time = self.iteration * dt
            for m in self.models:
                m.after_step(self.iteration, self.sim_time, dt)
            for cb in self._callbacks:
                cb(self.iteration, self.sim_time, dt)

    def run(
        self,
        duration: float | None = None,
        real_time: bool = False,
        should_stop: Callable[[], bool] | None = None,
    ) -> None:
        """Step for ``duration`` simulated seconds or until ``should_stop()`` (see run_world)."""
        run_world(self, duration, real_time, should_stop)

    def shutdown(self) -> None:
        try:
            self.client.disconnect()
        except pybullet.error:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.shutdown()
