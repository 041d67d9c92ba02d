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
The plan's tables for the assembly kernel, and its per-cycle call (``CyclePlan.update``'s twin).

Made at configuration from a :class:`~orca_ros.optim.cycle_plan.CyclePlan` and the first level's
problem, which from then on is built by the kernel (``WeightedProblem.prebuilt``).
"""

from __future__ import annotations

import numpy as np

from ...common.task_base import ActivationState

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)


class PlanAssembly:
    def __init__(self, plan, problem0):
        from . import assembly  # noqa: PLC0415

        assembly.warm_up()
        self.k = assembly
        self.plan = plan
        lay = plan.layout
        i64 = np.int64
        self.tasks = list(plan.tasks)
        self.ew = np.zeros(max(1, len(self.tasks)))
        self.diag = list(plan.diagonal_tasks)
        self.dg_ew = np.zeros(len(self.diag))
        self.dg_tab = np.array(
            [[r.start, r.stop - r.start, t.diagonal_columns.start]
             for t, r in zip(self.diag, plan.diagonal_rows)],
            dtype=i64,
        ).reshape(-1, 3)
        self.n0 = plan.level_rows[0].stop if plan.level_rows else 0
        self.nd0 = 1 + (len(plan.diagonal[0]) if plan.diagonal else 0)
        self.cons = plan.eq + plan.ineq
        rows = [(1, r.start, r.stop - r.start) for r in plan._eq_rows] + [
            (0, plan.n_eq + r.start, r.stop - r.start) for r in plan._in_rows
        ]
        self.con_tab = np.array([[e, r0, n, 0] for e, r0, n in rows], dtype=i64).reshape(-1, 4)
        self.con_on = np.zeros(len(self.cons), dtype=i64)
        self.boxes = plan.soft_box + plan.hard_box
        self.box_on = np.zeros(max(1, len(self.boxes)), dtype=i64)
        self.nsoft = len(plan.soft_box)
        self.problem = problem0
        self.WE = np.zeros((max(1, self.n0), lay.nx))
        problem0.prebuilt = True
        self.jb, self.nj, self.nx = lay.nbase, lay.ndof, lay.nx

    def update(self) -> None:
        """Write the flags and effective weights, run the kernel, then the contacts' wrench box."""
        ew = self.ew
        for i, t in enumerate(self.tasks):
            ew[i] = t.weight * t._ramp_factor if t.state not in _INACTIVE else 0.0
        dg = self.dg_ew
        for i, t in enumerate(self.diag):
            dg[i] = t.weight * t._ramp_factor if t.state not in _INACTIVE else 0.0
        on = self.con_on
        for i, c in enumerate(self.cons):
            on[i] = c.state not in _INACTIVE
        on = self.box_on
        for i, c in enumerate(self.boxes):
            on[i] = c.state not in _INACTIVE
        plan, p = self.plan, self.problem
        plan.box_conflicts += self.k.assemble(
            plan.E, plan.f, plan.w, plan.sel, plan.row_task, ew,
            plan.diag_f, plan.diag_sel, plan.diag_colw, plan.diag_ws, plan.diag_wsf,
            self.dg_tab, dg, self.n0, self.nd0, p.H, p.g, self.WE,
            plan.M, plan.lo, plan.hi, self.nx, plan.n_eq, self.con_tab, self.con_on,
            plan.box_lb, plan.box_ub, self.box_on, self.nsoft, self.jb, self.nj,
        )
        for c in plan.contacts:
            ws = c.wrench_slice()
            if c.state not in _INACTIVE:
                plan.lbox[ws] = c.wrench_lower
                plan.ubox[ws] = c.wrench_upper
            else:
                plan.lbox[ws] = 0.0
                plan.ubox[ws] = 0.0
