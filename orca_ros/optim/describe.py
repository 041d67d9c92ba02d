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
"""Human-readable description of a controller's stack (``Controller.describe`` / ``print``)."""

from __future__ import annotations

import numpy as np

from .resolution_strategy import ResolutionStrategy


def describe_controller(c) -> str:
    """
    Text view of a controller.

    strategy, solver, robot, levels with their tasks, constraints, last command.
    """
    lay = c.layout
    lines = [
        f"Controller '{c.name}' ({c.resolution_strategy.value}, solver {c.solver.value}); "
        f"robot '{c.robot.name}' {lay.ndof} dof, {'floating' if lay.nbase else 'fixed'} base, "
        f'QP variables {lay.nx}',
        f'  last return code: {c.get_return_code().value}',
    ]
    if c.resolution_strategy is ResolutionStrategy.ONE_LEVEL_WEIGHTED:
        lines.append('  tasks (one weighted level):')
        lines += [f'    {t.describe()}' for t in c.registry.tasks]
    else:
        problems = [c.get_problem_at_level(lev) for lev in c.get_levels()]
        lines.append(
            f'  tasks, {len(problems)} priority level(s), highest first '
            f'(+ {c.global_regularisation.describe()} in each):'
        )
        for p, own in zip(problems, c.get_level_tasks()):
            state = p.return_code.value
            lines.append(f'    level {p.level} [{state}]:')
            lines += [f'      {t.describe()}' for t in own]
        if c.resolution_strategy is ResolutionStrategy.GENERALIZED:
            lines.append(
                '  priorities (default 1 = strict between levels): '
                + (
                    ', '.join(f'{h} > {lo}: {a:g}' for (h, lo), a in c.priorities.items())
                    or 'all strict'
                )
            )
    lines.append('  constraints:')
    lines += [f'    {k.describe()}' for k in c.registry.constraints]
    if c.solution_found():
        with np.printoptions(precision=4, suppress=True):
            lines.append(f'  joint acceleration command: {c.get_joint_acceleration_command()}')
            lines.append(f'  joint torque command:       {c.get_joint_torque_command()}')
    return '\n'.join(lines)
