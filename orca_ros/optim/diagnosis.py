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
Which constraints stand in a task's way, or make a problem infeasible: ``diagnose(controller)``.

Off the control path (a call after a failed or surprising cycle), on the top priority level's
problem as the last ``update()`` built it:

* **infeasible problem**: each constraint group (one constraint object: the dynamics, a torque,
  position or velocity limit, a contact's friction cone, its existence condition, its wrench
  bounds) is dropped in turn; the groups whose removal makes the problem solvable are the conflict,
  named together (every one of them is part of every conflicting set);
* **solvable problem with a task far from its target**: each group is dropped in turn and the
  problem solved again; a group whose removal cuts a task's weighted residual by more than half is
  reported with that task, e.g. ``('ee', 'torque_limit')``: the torque limit keeps the end effector
  from its commanded acceleration.

One cold QP per group (DAQP): milliseconds, not a cycle's microseconds.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .solvers import make_backend, QPSolver, ReturnCode


@dataclass
class Diagnosis:
    feasible: bool
    conflicting_constraints: list = field(default_factory=list)  # infeasible: the culprits
    blocked_tasks: list = field(default_factory=list)  # (task, constraint, residual ratio)
    details: dict = field(default_factory=dict)  # culprit -> what it says of itself (explain())

    def text(self) -> str:
        if not self.feasible:
            if not self.conflicting_constraints:
                return 'infeasible, and no single constraint removal restores feasibility'
            return 'infeasible: conflicting constraints ' + ', '.join(
                f'{c} ({self.details[c]})' if self.details.get(c) else c
                for c in self.conflicting_constraints
            )
        if not self.blocked_tasks:
            return 'feasible; no constraint keeps a task from its target'
        return '; '.join(
            f"task '{t}' held back by constraint '{c}' (residual x{r:.2g} without it)"
            for t, c, r in self.blocked_tasks
        )


class _Groups:
    """The top level's constraint rows, by constraint object, and the QP without any of them."""

    def __init__(self, controller):
        self.problem = p = controller.get_problem_at_level(0)
        self.plan = plan = p.plan
        self.nx = p.layout.nx
        self.H, self.g = p.H.copy(), p.g.copy()
        self.A, self.b = plan.A.copy(), plan.b.copy()
        self.C, self.l, self.u = plan.C.copy(), plan.l.copy(), plan.u.copy()
        self.groups = []  # (name, kind, payload)
        for c, rows in zip(plan.eq, plan.eq_rows):
            if c.is_computing():
                self.groups.append((c.name, 'eq', rows))
        for c, rows in zip(plan.ineq, plan.in_rows):
            if c.is_computing():
                self.groups.append((c.name, 'in', rows))
        for c in plan.soft_box + plan.hard_box:
            if c.is_computing():
                self.groups.append((c.name, 'box', c))
        for c in plan.contacts:
            if c.is_computing():
                self.groups.append((f'{c.name} wrench bounds', 'wrench', c))

    def _box(self, without):
        plan, lay = self.plan, self.problem.layout
        lo, hi = np.full(self.nx, -np.inf), np.full(self.nx, np.inf)
        jl, jh = lo[lay.joint_acc], hi[lay.joint_acc]
        for c in plan.soft_box + plan.hard_box:
            if c.is_computing() and c is not without:
                np.maximum(jl, c.lb, out=jl)
                np.minimum(jh, c.ub, out=jh)
        bad = jl > jh  # as the plan does for soft boxes that disagree: a feasible compromise
        jl[bad] = jh[bad] = 0.5 * (jl[bad] + jh[bad])
        for c in plan.contacts:
            ws = c.wrench_slice()
            if not c.is_computing():
                lo[ws] = hi[ws] = 0.0
            elif c is not without:
                lo[ws], hi[ws] = c.wrench_lower, c.wrench_upper
        return lo, hi

    def solve(self, drop=None):
        """Solve without group ``drop`` (an index, or None); return (success, x)."""
        keep_eq = np.ones(self.A.shape[0], dtype=bool)
        keep_in = np.ones(self.C.shape[0], dtype=bool)
        without = None
        if drop is not None:
            name, kind, payload = self.groups[drop]
            if kind == 'eq':
                keep_eq[payload] = False
            elif kind == 'in':
                keep_in[payload] = False
            else:
                without = payload
        lbox, ubox = self._box(without)
        A, b = self.A[keep_eq], self.b[keep_eq]
        C, lo, up = self.C[keep_in], self.l[keep_in], self.u[keep_in]
        backend = make_backend(
            QPSolver.DAQP, self.nx, A.shape[0], C.shape[0],
            scale=self.problem.layout.variable_scale,
        )
        backend.max_iterations = 10_000
        code = backend.solve(self.H, self.g, A, b, C, lo, up, lbox, ubox)
        return code is ReturnCode.SUCCESS, backend.x.copy()


def _residuals(controller, x) -> dict:
    """Weighted residual of every computing task of the top level at x."""
    out = {}
    tasks = [t for t in controller.get_tasks() if t.is_computing() and t.rows() > 0]
    top = min((t.level for t in tasks), default=0)
    for t in tasks:
        if t.level != top:
            continue
        r = np.sqrt(np.maximum(t.selection, 0.0)) * (t.E @ x - t.f)
        out[t.name] = float(np.linalg.norm(r))
    return out


def _details(controller, names) -> dict:
    """Return what each named constraint with an ``explain()`` method says of its last rows."""
    out = {}
    for name in names:
        try:
            explain = getattr(controller.get_constraint(name), 'explain', None)
        except (KeyError, ValueError):
            continue  # a group that is no constraint of its own (a contact's wrench bounds)
        if explain is not None:
            out[name] = explain()
    return out


def diagnose(controller, ratio: float = 0.5, tolerance: float = 1e-6) -> Diagnosis:
    """Name what conflicts in the last cycle's top-level problem (see the module docstring)."""
    groups = _Groups(controller)
    ok, x = groups.solve()
    if not ok:
        culprits = [
            groups.groups[i][0] for i in range(len(groups.groups)) if groups.solve(i)[0]
        ]
        return Diagnosis(feasible=False, conflicting_constraints=culprits,
                         details=_details(controller, culprits))
    base = _residuals(controller, x)
    blocked = []
    for i, (name, _, _) in enumerate(groups.groups):
        ok_i, x_i = groups.solve(i)
        if not ok_i:
            continue
        for task, r in _residuals(controller, x_i).items():
            r0 = base[task]
            if r0 > tolerance and r < ratio * r0:
                blocked.append((task, name, r / r0))
    blocked.sort(key=lambda item: item[2])
    return Diagnosis(feasible=True, blocked_tasks=blocked)
