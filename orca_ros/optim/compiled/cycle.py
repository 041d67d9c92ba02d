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
its plan: the kernels are compiled (or loaded from numba's disk cache) here, never in a control
cycle. :meth:`update` replaces the reference path's loop over the objects' ``update``.
"""

from __future__ import annotations

import time

from .lowering import lower
from .plan_assembly import PlanAssembly
from ...utils.logger import get_logger

_LOG = get_logger('compiled')


class CompiledCycle:
    def __init__(self, controller, plan):
        from . import kernels  # noqa: PLC0415 - numba loads (and compiles) here, at configuration

        t0 = time.perf_counter()
        kernels.warm_up()
        self.items = []  # (lowered object or None, the object), in the reference path's order
        self.in_python: dict[str, str] = {}  # object name -> why it is not lowered
        for obj in controller._updated:
            low, why = lower(obj, plan, kernels)
            self.items.append((low, obj))
            if low is None:
                self.in_python[obj.name] = why
        self.lowered = sum(low is not None for low, _ in self.items)
        self.assembly = PlanAssembly(plan, controller._problems[0])
        self.compile_seconds = time.perf_counter() - t0

    def update(self, t: float, dt: float) -> None:
        for low, obj in self.items:
            if low is None:
                obj.update(t, dt)
            elif low.step(t):
                low.fill(t, dt)

    def assemble(self) -> None:
        """The plan's update and the first level's H and g (CyclePlan.update's twin)."""
        self.assembly.update()

    def describe(self) -> str:
        rest = ', '.join(f'{n} ({why})' for n, why in self.in_python.items())
        return (
            f'compiled cycle: {self.lowered} of {len(self.items)} objects by kernel'
            + (f'; in Python: {rest}' if rest else '')
            + f' (kernels ready in {self.compile_seconds:.2f} s)'
        )
