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
The QP of each priority level, made once at configuration, and their solve in priority order.

Level 0 is a :class:`WeightedProblem`; each level below is a :class:`LowerLevelProblem` that keeps
the optimum of the levels above (strictly, or within the bands of the GENERALIZED strategy, whose
reference problems, the levels' costs without locks, are made here too).
"""

from __future__ import annotations

import math

from .elastic_contacts import ElasticContacts
from .lower_level_problem import LowerLevelProblem
from .resolution_strategy import ResolutionStrategy
from .solvers import ReturnCode
from .weighted_problem import WeightedProblem
from ..utils.logger import get_logger

_LOG = get_logger('optim')


def tasks_by_level(user_tasks, strategy) -> tuple[list[int], list[list]]:
    """Return (the priority levels, highest first; the user tasks of each)."""
    if strategy is ResolutionStrategy.ONE_LEVEL_WEIGHTED:
        return [0], [list(user_tasks)]
    levels = sorted({t.level for t in user_tasks}) or [0]
    return levels, [[t for t in user_tasks if t.level == lev] for lev in levels]


class PriorityLevels:
    def __init__(self, plan, user_tasks, strategy, solver, lower_damping: float = 0.0):
        levels, self.level_tasks = tasks_by_level(user_tasks, strategy)
        generalized = strategy is ResolutionStrategy.GENERALIZED
        self.problems, self.references = [], []
        for i, lev in enumerate(levels):
            own_diag = plan.diagonal[i]
            above_diag = [t for d in plan.diagonal[:i] for t in d]
            if i == 0:
                self.problems.append(
                    WeightedProblem(
                        plan, plan.level_rows[0], solver, level=lev, diagonal_tasks=own_diag
                    )
                )
                self.references.append(None)
                continue
            # levels in order, each weighted inside, each keeping (some of) the optimum of the
            # levels above; GENERALIZED: the costs of the levels above stay in the level (constant
            # when locked)
            above = [t for t in user_tasks if t.level < lev]
            cost = plan.prefix_rows[i] if generalized else plan.level_rows[i]
            cost_diag = above_diag + own_diag if generalized else own_diag
            self.problems.append(
                LowerLevelProblem(
                    plan, cost, solver, level=lev, locked_tasks=above, diagonal_tasks=cost_diag
                )
            )
            self.references.append(
                WeightedProblem(
                    plan,
                    plan.prefix_rows[i],
                    solver,
                    level=lev,
                    diagonal_tasks=above_diag + own_diag,
                )
                if generalized
                else None
            )
        self.watch = None  # a Touched told of every change of the damping (the compiled cascade's)
        self.set_temporal_damping(lower_damping)
        self.elastic = ElasticContacts(plan, solver)
        self.contacts_relaxed = False  # the last cycle's level 0 was solved with elastic contacts

    def set_temporal_damping(self, mu: float) -> None:
        """Damp every level below the first in time (LowerLevelProblem.set_temporal_damping)."""
        if self.watch is not None:
            self.watch.touched = True
        for p in self.problems[1:]:
            p.set_temporal_damping(mu)

    def damping_scale(self, i: int, priorities) -> float:
        """
        Return what level i's temporal damping is relative to this cycle.

        The summed weights of its own tasks, ramps left out (a task ramping in meets a damping
        at its full weight, and moves from what the robot does smoothly). Under GENERALIZED, with
        alpha the level's priority (the largest alpha of a locked task over it): alpha (W_own +
        sqrt(1 - alpha) W_up), W_up the weights of the levels above. 0 at alpha = 0, where the
        level is the weighted solution exactly; the strict cascade's damping at alpha = 1;
        continuous in between. The level's cost holds the upper tasks' too, which push it
        across the active set of their bands as long as those are open: damped relative to its own
        weights only (posture 1e-3 under tasks of weight 1 and 10), a level jumped in a cycle as a
        band row came active, and the torques stepped (the Panda stack's closed-loop alpha ramp).
        The upper share removes that with a power of (1 - alpha) below 1, not with power 1: it
        must fade slower than the bands close, (1 - alpha)^2.
        """
        own = self.level_tasks[i]
        w = sum(t.weight for t in own if t.is_computing())
        if self.references[i] is not None:
            a = max((priorities.level_priority(t, own) for t in self.problems[i].locked),
                    default=1.0)
            up = sum(t.weight for j in range(i) for t in self.level_tasks[j] if t.is_computing())
            w = a * (w + math.sqrt(1.0 - a) * up)
        return w

    def first_failed(self, problem, code, deadline, max_iterations):
        """
        Level 0 failed with ``code``: solve it with elastic contacts where there are contacts.

        Returns (level 0's problem, the final code, False).
        """
        if self.elastic.available:
            elastic = self.elastic.solve(problem, deadline, max_iterations)
            if elastic is ReturnCode.SUCCESS:
                problem.x[:] = self.elastic.x
                problem.return_code = elastic
                self.contacts_relaxed = True
                return problem, elastic, False
        return problem, code, False

    def solve(self, deadline, max_iterations, priorities, name: str):
        """
        Solve the level(s) in priority order.

        Returns (the problem holding the final solution, its code, whether a level was dropped).
        """
        problems = self.problems
        self.contacts_relaxed = False
        x_above = None
        solved = problems[0]
        code = ReturnCode.SUCCESS
        for i, problem in enumerate(problems):
            if i > 0:
                own = self.level_tasks[i]
                if not any(t.get_effective_weight() > 0.0 for t in own):
                    # nothing to optimise here: the solution above stands. The level has no
                    # solution of its own this cycle: the next it solves is damped towards the
                    # solution above, not towards one from before it was switched off
                    problem.prev_ok[0] = 0
                    continue
                band = None
                if self.references[i] is not None:
                    self.references[i].set_budget(deadline, max_iterations)
                    band = priorities.bands(problem, own, self.references[i], x_above)
                problem.lock(x_above, band)
                problem.damping_scale = self.damping_scale(i, priorities)
            problem.build()
            problem.set_budget(deadline, max_iterations)
            code = problem.solve()
            if code is not ReturnCode.SUCCESS:
                if i == 0:
                    return self.first_failed(problem, code, deadline, max_iterations)
                # lower levels are feasible by construction (see lower_level_problem); should a
                # solver still fail, the level is dropped for this cycle: the solution above
                # satisfies every constraint
                _LOG.debug(
                    "controller '%s': level %d not solved (%s), keeping level %d's solution",
                    name,
                    problem.level,
                    code.value,
                    solved.level,
                )
                return solved, ReturnCode.SUCCESS, True
            x_above, solved = problem.x, problem
        return solved, code, False
