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
The plan's tables for the assembly kernel, and its per-cycle flags (``CyclePlan.update``'s twin).

Made at configuration from a :class:`~orca_ros.optim.cycle_plan.CyclePlan` and the first level's
problem, which from then on is built by the kernel (``WeightedProblem.prebuilt``).
"""

from __future__ import annotations

import numpy as np

from ...common.task_base import ActivationState

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)


class PlanAssembly:
    def __init__(self, plan, problem0):
        self.plan = plan
        lay = plan.layout
        i64 = np.int64
        self.tasks = list(plan.tasks)
        self.ew = np.zeros(max(1, len(self.tasks)))
        self.nw = np.zeros(max(1, len(self.tasks)))  # weights, ramps left out (0 when inactive)
        self.diag = list(plan.diagonal_tasks)
        self.dg_ew = np.zeros(len(self.diag))
        self.dg_nw = np.zeros(len(self.diag))
        self.dg_tab = np.array(
            [[r.start, r.stop - r.start, t.diagonal_columns.start]
             for t, r in zip(self.diag, plan.diagonal_rows)],
            dtype=i64,
        ).reshape(-1, 3)
        self.n0 = plan.level_rows[0].stop if plan.level_rows else 0
        self.nd0 = 1 + (len(plan.diagonal[0]) if plan.diagonal else 0)
        self.cons = plan.eq + plan.ineq
        rows = [(1, r.start, r.stop - r.start) for r in plan.eq_rows] + [
            (0, plan.n_eq + r.start, r.stop - r.start) for r in plan.in_rows
        ]
        self.con_tab = np.array([[e, r0, n, 0] for e, r0, n in rows], dtype=i64).reshape(-1, 4)
        self.con_on = np.zeros(max(1, len(self.cons)), dtype=i64)
        self.boxes = plan.soft_box + plan.hard_box
        self.box_on = np.zeros(max(1, len(self.boxes)), dtype=i64)
        self.nsoft = len(plan.soft_box)
        self.problem = problem0
        self.WE = np.zeros((max(1, self.n0), lay.nx))
        problem0.prebuilt = True

    def arrays(self) -> dict:
        """Return the workspace fields of the plan and of the first level's problem."""
        p, lay = self.plan, self.plan.layout
        return {
            'E': p.E, 'f': p.f, 'w': p.w, 'sel': p.sel, 'row_task': p.row_task, 'ew': self.ew,
            'dg_f': p.diag_f, 'dg_sel': p.diag_sel, 'dg_colw': p.diag_colw, 'dg_ws': p.diag_ws,
            'dg_wsf': p.diag_wsf, 'dg_tab': self.dg_tab, 'dg_ew': self.dg_ew,
            'H': self.problem.H, 'g': self.problem.g, 'WE': self.WE, 'M': p.M, 'lo': p.lo,
            'hi': p.hi, 'con_tab': self.con_tab, 'con_on': self.con_on, 'box_lb': p.box_lb,
            'box_ub': p.box_ub, 'box_on': self.box_on, 'nx': lay.nx, 'ne': p.n_eq,
            'n0': self.n0, 'nd0': self.nd0, 'nsoft': self.nsoft, 'jb': lay.nbase,
            'nj': lay.ndof,
        }

    def flags(self) -> None:
        """Write this cycle's effective weights and on/off flags, after every object's step."""
        for ew, nw, tasks in ((self.ew, self.nw, self.tasks), (self.dg_ew, self.dg_nw, self.diag)):
            for i, t in enumerate(tasks):
                on = t.state not in _INACTIVE
                nw[i] = t.weight if on else 0.0
                ew[i] = t.weight * t.ramp_factor if on else 0.0
        on = self.con_on
        for i, c in enumerate(self.cons):
            on[i] = c.state not in _INACTIVE
        on = self.box_on
        for i, c in enumerate(self.boxes):
            on[i] = c.state not in _INACTIVE

    def contacts(self) -> None:
        """Set the contacts' wrench bounds (Python objects), as CyclePlan._update_box does."""
        plan = self.plan
        for c in plan.contacts:
            ws = c.wrench_slice()
            if c.state not in _INACTIVE:
                plan.lbox[ws] = c.wrench_lower
                plan.ubox[ws] = c.wrench_upper
            else:
                plan.lbox[ws] = 0.0
                plan.ubox[ws] = 0.0
