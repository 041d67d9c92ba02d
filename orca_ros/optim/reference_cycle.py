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
One control cycle of a configuration, in Python: the reference the compiled cycle matches.

Made by the controller whenever its structure changed (a task or constraint added or removed, a
level changed, contacts re-laid out). It holds the configuration's products: the stacked rows of
every object (:class:`~.cycle_plan.CyclePlan`), the problem of each priority level
(:class:`~.priority_levels.PriorityLevels`) and the objects that have rows to compute.

:meth:`run` is the cycle: the layout's dynamics terms, each object's rows, the plan's weights and
bounds, the levels solved in priority order, the last level's solution written into the
controller's :class:`~.solution_output.SolutionOutput`. The compiled cycle
(:class:`~.compiled.cycle.CompiledCycle`, made from this one) has the same interface and gives the
same results by numba kernels.
"""

from __future__ import annotations

from .cycle_plan import CyclePlan
from .priority_levels import PriorityLevels, tasks_by_level
from .solvers import ReturnCode

_SUCCESS = ReturnCode.SUCCESS


class ReferenceCycle:
    """
    A configuration and its cycle in Python (see the module).

    ``registry``: the controller's :class:`~.task_registry.TaskRegistry`; ``priorities``: its
    :class:`~.generalized.GeneralizedPriorities`, read every cycle; ``output``: its
    :class:`~.solution_output.SolutionOutput`.
    """

    def __init__(self, name: str, registry, layout, strategy, solver, lower_damping: float,
                 priorities, output):
        self.name, self.registry, self.layout = name, registry, layout
        self.solver, self.priorities, self.output = solver, priorities, output
        user = registry.user_tasks()
        _, level_tasks = tasks_by_level(user, strategy)
        self.regularisation, self.dynamics = registry.internal
        self.plan = CyclePlan(layout, level_tasks, self.regularisation, registry.constraints)
        self.levels = PriorityLevels(self.plan, user, strategy, solver, lower_damping)
        # objects without rows for this robot have nothing to compute; contacts: their ramps
        self.objects = [
            o
            for o in registry.tasks + registry.constraints
            if o.rows() > 0 or getattr(o, 'is_contact', False)
        ]

    def run(self, t: float, dt: float, deadline, max_iterations):
        """
        Compute every row for the robot's state, solve the levels, write the solution out.

        ``deadline``: the perf_counter time the solves must end by (None: unbounded);
        ``max_iterations``: each solve's cap (None: the solver's default). Returns (the
        ReturnCode, whether a level below the first was dropped): SUCCESS with the solution in
        the output's buffers, or the first level's failure, the buffers left as they were.
        """
        self.layout.update()
        for obj in self.objects:
            obj.update(t, dt)
        self.plan.update()
        problem, code, dropped = self.levels.solve(deadline, max_iterations, self.priorities,
                                                   self.name)
        if code is _SUCCESS:
            self.output.write_out(problem.x)
        return code, dropped

    def describe(self) -> str:
        return f'reference cycle: {len(self.objects)} objects in Python'
