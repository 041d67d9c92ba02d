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
The compiled cycle of one controller configuration: lowered objects by kernel, the rest in Python.

Made by the controller at configuration (``Controller(..., compiled=True)``, the default), after
its plan and problems: the kernel is compiled (or loaded from numba's disk cache) here, never in
a control cycle. Per cycle, :meth:`update` runs the Python objects' updates and the lowered
objects' life cycles, then one kernel call (:mod:`.cycle_kernel`) on the cycle's workspace
(:mod:`.workspace`): it replaces the objects' updates, ``CyclePlan.update`` and the first level's
build.
"""

from __future__ import annotations

import time

from . import cycle_kernel, fill
from .lowering import lower, Tables
from .plan_assembly import PlanAssembly
from .workspace import make_workspace
from ...utils.logger import get_logger

_LOG = get_logger('compiled')


class CompiledCycle:
    def __init__(self, controller, plan):
        start = time.perf_counter()
        robot = controller.robot
        self.python = []  # objects that run their own update, in the reference path's order
        self.lowered = []
        self.in_python: dict[str, str] = {}  # object name -> why it is not lowered
        for obj in controller._updated:
            low, why = lower(obj)
            if low is None:
                self.python.append(obj)
                self.in_python[obj.name] = why
            else:
                self.lowered.append(low)
        self.tables = t = Tables(self.lowered, robot)
        for k, low in enumerate(self.lowered):
            low.bind(t, k, plan)
        self.n_objects = len(controller._updated)
        self.plan = plan
        self.assembly = PlanAssembly(plan, controller._problems[0])
        self.problem = controller._problems[0]
        self.robot, self.layout = robot, controller.layout
        self._bind_data()
        # compile (or load) the kernel for this configuration's types, every object off: the
        # arrays it writes are rewritten by the first cycle
        t.tab[:, 1] = 0
        cycle_kernel.run(self.ws, 1e-3)
        self.compile_seconds = time.perf_counter() - start

    def _bind_data(self) -> None:
        """
        Take the robot's Pinocchio Data (its live arrays) and model (bodies, frames).

        Again whenever the robot replaces them: re-welding locked joints that moved
        (``RobotModel.set_locked_joint_positions``) makes a new model and Data.
        """
        robot, lay, t = self.robot, self.layout, self.tables
        d, nb = robot.data, lay.nbase
        views = fill.data_views(robot.model, d)
        if views is None:
            raise RuntimeError("Pinocchio's Data is not laid out as the kernels read it")
        self.data = d
        t.set_bodies(robot.model)
        for low in self.lowered:
            low.rebind_model()
        # the torque map (T, t0): Pinocchio's M and nle themselves without contacts (what
        # layout.update points to every cycle), the layout's own arrays with contacts
        T, t0 = (d.M[nb:], d.nle[nb:]) if lay.n_wrenches == 0 else (lay._T, lay._t0)
        self.ws = make_workspace(
            J=d.J, oMi=views[0], vj=views[1], aj=views[2], q=robot._q, v=robot._v,
            v_pin=robot._v_pin, T=T, t0=t0, cart=t.cart, cart_sup=t.cart_sup, jrec=t.jrec,
            lims=t.lims, pacc=t.pacc, tab=t.tab, par=t.par, tmp=t.tmp,
            com=d.com[0], vcom=d.vcom[0], Jcom=d.Jcom, body=t.body, crec=t.crec,
            **self.assembly.arrays(),
        )

    def update(self, t: float, dt: float) -> None:
        """
        Fill every object's rows and assemble the plan.

        What the reference path's object loop, CyclePlan.update and the first level's build do.
        """
        if self.robot.data is not self.data:
            self._bind_data()
        for obj in self.python:
            obj.update(t, dt)
        for low in self.lowered:
            low.step(t)
        self.assembly.flags()
        flags = cycle_kernel.run(self.ws, dt)
        self.plan.box_conflicts += flags & 1
        self.problem.built_finite = not flags & 2
        self.assembly.contacts()

    def describe(self) -> str:
        rest = ', '.join(f'{n} ({why})' for n, why in self.in_python.items())
        return (
            f'compiled cycle: {len(self.lowered)} of {self.n_objects} objects by kernel'
            + (f'; in Python: {rest}' if rest else '')
            + f' (kernels ready in {self.compile_seconds:.2f} s)'
        )
