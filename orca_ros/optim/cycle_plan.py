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
The compiled control cycle: every task's and constraint's rows stacked once, at configuration.

When the controller's structure changes (a task or constraint added or removed, a level changed,
contacts re-laid out), :class:`CyclePlan` allocates the stacked arrays of the whole problem and
hands each object *views* on its own rows:

* task rows ``E`` (rows x nx), ``f``, one weight per row ``w`` (weight x ramp x selection), ordered
  level by level so that the rows of a level, and of every level down to it, are contiguous slices.
  Tasks whose E selects variables (posture, regularisation: ``diagonal_columns``) are not stacked:
  they add to the Hessian's diagonal, from ``ws`` (weight x selection) and ``wsf`` (ws x f)
  refreshed here;
* constraint rows in the layout of the default solver (DAQP): one matrix ``M = [A; C]`` and one
  bound vector per side, ``lo = [lbox; b; l]`` and ``hi = [ubox; b; u]``, with ``A, C, b, l, u,
  lbox, ubox`` views on them (the equalities' right-hand side is copied into ``hi`` once per
  cycle);
* variable bounds ``lbox <= x <= ubox``, merged once per cycle from the joint box constraints and
  the contacts.

Every cycle each object writes its values in place (no allocation); :meth:`update` refreshes the
row weights and the variable bounds, and relaxes the rows of constraints that just switched off;
each priority level's problem then forms its Hessian and gradient from its slice with two BLAS
calls (see ``WeightedProblem.build``). The constraints are filled once per cycle and shared by
every level.
"""

from __future__ import annotations

import numpy as np


def _stack(objects, width: int, rows_of):
    """(offsets, total) of objects stacked by their number of rows."""
    out, k = [], 0
    for o in objects:
        m = rows_of(o)
        out.append(slice(k, k + m))
        k += m
    return out, k


class CyclePlan:
    def __init__(self, layout, levels, regularisation, constraints):
        """
        ``levels``.

        The user tasks of each priority level, highest first (one entry for a single weighted
        level); ``regularisation``: the global regularisation task (identity rows, kept as a
        diagonal).
        """
        self.layout = layout
        nx = layout.nx
        self.regularisation = regularisation
        dense = [[t for t in lev if t.diagonal_columns is None] for lev in levels]
        self.diagonal = [[t for t in lev if t.diagonal_columns is not None] for lev in levels]
        tasks = [t for lev in dense for t in lev]
        self.tasks = tasks
        self.task_rows, n = _stack(tasks, nx, lambda t: t.rows())
        self.E = np.zeros((n, nx))
        self.f = np.zeros(n)
        self.w = np.zeros(n)
        self.sel = np.zeros(n)  # the tasks' selection vectors, packed (views rebound below)
        self.row_task = np.zeros(n, dtype=np.int64)  # dense row -> index in self.tasks
        for i, (t, rows) in enumerate(zip(tasks, self.task_rows)):
            self.E[rows] = t.E
            self.f[rows] = t.f
            self.sel[rows] = t.selection
            self.row_task[rows] = i
            t.E, t.f, t.selection = self.E[rows], self.f[rows], self.sel[rows]
        # diagonal tasks (every level's problem has the regularisation): f, selection, column
        # weights and the products ws (weight x selection x column weight) and wsf (ws x f),
        # packed one task after another; the tasks' f and selection are views on them
        self.diagonal_tasks = [regularisation] + [t for lev in self.diagonal for t in lev]
        self.diagonal_rows, m = _stack(self.diagonal_tasks, nx, lambda t: t.rows())
        self.diag_f, self.diag_sel = np.zeros(m), np.zeros(m)
        self.diag_colw, self.diag_ws, self.diag_wsf = np.ones(m), np.zeros(m), np.zeros(m)
        self.ws, self.wsf = {}, {}
        for t, rows in zip(self.diagonal_tasks, self.diagonal_rows):
            self.diag_f[rows] = t.f
            self.diag_sel[rows] = t.selection
            if t.column_weights is not None:
                self.diag_colw[rows] = t.column_weights
            t.f, t.selection = self.diag_f[rows], self.diag_sel[rows]
            self.ws[id(t)], self.wsf[id(t)] = self.diag_ws[rows], self.diag_wsf[rows]
        self._weight_keys = [None] * len(tasks)
        self._diagonal_keys = [None] * len(self.diagonal_tasks)
        # dense rows of each level, and of each level together with every level above it
        self.level_rows, self.prefix_rows, k = [], [], 0
        for lev in dense:
            m = sum(t.rows() for t in lev)
            self.level_rows.append(slice(k, k + m))
            k += m
            self.prefix_rows.append(slice(0, k))
        # constraints: objects without rows for this robot cost nothing at run time
        with_rows = [c for c in constraints if c.rows() > 0]
        self.eq = [c for c in with_rows if c.kind == 'equality']
        self.ineq = [c for c in with_rows if c.kind == 'inequality']
        self.soft_box = [c for c in with_rows if c.kind == 'box' and not c.hard]
        self.hard_box = [c for c in with_rows if c.kind == 'box' and c.hard]
        self.contacts = [c for c in constraints if getattr(c, 'is_contact', False)]
        eq_rows, self.n_eq = _stack(self.eq, nx, lambda c: c.rows())
        in_rows, self.n_in = _stack(self.ineq, nx, lambda c: c.rows())
        ne, ni = self.n_eq, self.n_in
        self.M = np.zeros((ne + ni, nx))
        self.lo = np.full(nx + ne + ni, -np.inf)
        self.hi = np.full(nx + ne + ni, np.inf)
        self.A, self.C = self.M[:ne], self.M[ne:]
        self.lbox, self.ubox = self.lo[:nx], self.hi[:nx]
        self.b, self._b_hi = self.lo[nx: nx + ne], self.hi[nx: nx + ne]
        self.b[:] = 0.0
        self.l, self.u = self.lo[nx + ne:], self.hi[nx + ne:]
        for c, rows in zip(self.eq, eq_rows):
            self.A[rows] = c.C
            self.b[rows] = c.lb
            c.C, c.lb, c.ub = self.A[rows], self.b[rows], self.b[rows]
        for c, rows in zip(self.ineq, in_rows):
            self.C[rows] = c.C
            self.l[rows] = c.lb
            self.u[rows] = c.ub
            c.C, c.lb, c.ub = self.C[rows], self.l[rows], self.u[rows]
        self.eq_rows, self.in_rows = eq_rows, in_rows
        self._relaxed = {id(c): False for c in self.eq + self.ineq}
        # joint box constraints' bounds, packed (views rebound): soft ones first, then hard
        boxes = self.soft_box + self.hard_box
        self.box_lb = np.zeros((len(boxes), layout.ndof))
        self.box_ub = np.zeros((len(boxes), layout.ndof))
        for k, c in enumerate(boxes):
            self.box_lb[k], self.box_ub[k] = c.lb, c.ub
            c.lb, c.ub = self.box_lb[k], self.box_ub[k]
        self._lbox_joints = self.lbox[layout.joint_acc]
        self._ubox_joints = self.ubox[layout.joint_acc]
        self.box_conflicts = 0

    # -------------------------------------------------------------- per cycle
    def update(self) -> None:
        """
        Row weights.

        Relaxation of switched-off constraints, variable bounds (after the objects' updates).
        """
        w, keys = self.w, self._weight_keys
        for i, (t, rows) in enumerate(zip(self.tasks, self.task_rows)):
            key = (t.get_effective_weight(), t.selection_version)
            if key != keys[i]:  # row weights change only with the ramps, weights and selections
                np.multiply(t.selection, key[0], out=w[rows])
                keys[i] = key
        for i, t in enumerate(self.diagonal_tasks):
            ws = self.ws[id(t)]
            key = (t.get_effective_weight(), t.selection_version)
            if key != self._diagonal_keys[i]:
                np.multiply(t.selection, key[0], out=ws)
                if t.column_weights is not None:
                    ws *= t.column_weights
                self._diagonal_keys[i] = key
            np.multiply(ws, t.f, out=self.wsf[id(t)])
        relaxed = self._relaxed
        for c, rows in zip(self.eq, self.eq_rows):
            if c.is_computing():
                relaxed[id(c)] = False
            elif not relaxed[id(c)]:
                self.A[rows] = 0.0
                self.b[rows] = 0.0
                relaxed[id(c)] = True
        for c, rows in zip(self.ineq, self.in_rows):
            if c.is_computing():
                relaxed[id(c)] = False
            elif not relaxed[id(c)]:
                self.l[rows] = -np.inf
                self.u[rows] = np.inf
                relaxed[id(c)] = True
        self._update_box()
        if self.n_eq:
            self._b_hi[:] = self.b

    def _update_box(self) -> None:
        for c in self.contacts:
            ws = c.wrench_slice()
            if c.is_computing():
                self.lbox[ws] = c.wrench_lower
                self.ubox[ws] = c.wrench_upper
            else:
                self.lbox[ws] = 0.0
                self.ubox[ws] = 0.0
        if not self.soft_box and not self.hard_box:
            return
        lo, hi = self._lbox_joints, self._ubox_joints  # views: merged in place
        first = True
        for c in self.soft_box:
            if c.is_computing():
                if first:
                    lo[:] = c.lb
                    hi[:] = c.ub
                    first = False
                else:
                    np.maximum(lo, c.lb, out=lo)
                    np.minimum(hi, c.ub, out=hi)
        if first:
            lo.fill(-np.inf)
            hi.fill(np.inf)
        elif (lo > hi).any():
            # position and velocity predictions disagree (e.g. fast motion near a limit): keep a
            # finite, feasible compromise rather than an empty set
            bad = lo > hi
            mid = 0.5 * (lo[bad] + hi[bad])
            lo[bad] = mid
            hi[bad] = mid
            self.box_conflicts += 1
        for c in self.hard_box:
            if c.is_computing():
                np.clip(lo, c.lb, c.ub, out=lo)
                np.clip(hi, c.lb, c.ub, out=hi)
