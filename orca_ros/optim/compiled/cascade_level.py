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
One priority level below the first, by kernel: its arrays, kernel state, frame and back-ends.

:mod:`.cascade`, which solves the levels in turn, makes one per level.

Made at configuration: the level's locks (its rows of the plan: dense or diagonal tasks), its
cost's rows (its own, or every level's down to it under GENERALIZED), the tasks above whose
weights share in its damping, the kernels compiled (or loaded) for its arrays' types.
"""

from __future__ import annotations

import math

import numpy as np

from . import lower_level as L
from .level_frame import framed_generalized, framed_strict, make_level_frame
from ..generalized import band_share
from ..solvers import direct_daqp
from ...utils.jit import entry


def _direct(nx, n_eq, n_in, scale, arrays, x, base=None):
    """Make a DAQP back-end by kernel on (H, g, M, lo, hi) writing x (base + its step)."""
    b = direct_daqp.DirectDAQPBackend(nx, n_eq, n_in, scale=scale)
    b.write_into(x, base)
    b.compile_for(*arrays)
    return b


class Level:
    """One level below the first: its problem, its kernel state, its DAQP back-ends by kernel."""

    def __init__(self, plan, assembly, levels, index):
        self.index = index
        self.problem = p = levels.problems[index]
        self.tasks = levels.level_tasks[index]
        reference = levels.references[index]
        lay = plan.layout
        nx, scale = lay.nx, lay.variable_scale
        dense = {id(t): i for i, t in enumerate(plan.tasks)}
        diag = {id(t): i for i, t in enumerate(plan.diagonal_tasks)}
        locks = []
        for t in p.locked:
            if id(t) in dense:
                k = dense[id(t)]
                locks.append([0, plan.task_rows[k].start, t.rows(), 0, k])
            else:
                k = diag[id(t)]
                locks.append([1, plan.diagonal_rows[k].start, t.rows(),
                              t.diagonal_columns.start, k])
        own_dg = list(plan.diagonal[index])
        # the cost: the level's rows (strict), or every level's down to it (GENERALIZED)
        rows, cost_dg = plan.level_rows[index], own_dg
        if reference is not None:
            rows = plan.prefix_rows[index]
            cost_dg = [t for d in plan.diagonal[:index] for t in d] + own_dg
        i64 = np.int64
        # GENERALIZED: the levels above, whose tasks' weights share in the damping
        upper = ([t for j in range(index) for t in levels.level_tasks[j]]
                 if reference is not None else [])
        nl, nc, ni = p.lock_rows(), p.n_eq_constraints, p.n_in
        # the damping's factors (by kernel), and the damping they were written for (nan: none;
        # read_priorities, which changes alpha, resets it)
        self.mu, self.mu_for = np.zeros(2), math.nan
        self.Hd, self.g2 = np.zeros((nx, nx)), np.zeros(nx)
        self.keep, self.ref_x, self.band = np.zeros(nl), np.zeros(nx), np.zeros(nl)
        self.Mb = np.zeros((nc + ni + nl, nx))
        self.lob, self.hib = np.zeros(nx + nc + ni + nl), np.zeros(nx + nc + ni + nl)
        self.state = L.make_level_state(
            plan.E, plan.f, plan.w, plan.sel, assembly.ew, assembly.nw, plan.diag_sel,
            plan.diag_ws, plan.diag_wsf, assembly.dg_ew, assembly.dg_nw, assembly.dg_tab, plan.M,
            plan.lo, plan.hi,
            np.array([0] + [diag[id(t)] for t in cost_dg], dtype=i64),
            np.array([dense[id(t)] for t in self.tasks if id(t) in dense], dtype=i64),
            np.array([diag[id(t)] for t in own_dg], dtype=i64),
            np.array(locks, dtype=i64).reshape(-1, 5), rows.start, rows.stop,
            np.array([dense[id(t)] for t in upper if id(t) in dense], dtype=i64),
            np.array([diag[id(t)] for t in upper if id(t) in diag], dtype=i64),
            p.H, p.g, p.stacked_M, p.b, p.stacked_lo, p.stacked_hi, levels.problems[index - 1].x,
            p.x_ref, p.x,
            p.prev_ok, p.damping_w, self.mu, self.Hd, self.g2, nc, ni, nx,
            self.keep, self.ref_x, self.band, self.Mb, self.lob, self.hib,
        )
        p.locked_backend = b = _direct(
            nx, p.n_eq, ni, scale, (self.Hd, self.g2, p.stacked_M, p.stacked_lo, p.stacked_hi),
            p.x, p.x_ref,
        )
        # compiled (or loaded) here, not in a cycle: prepare, then solve, in one call when warm
        self.fused = entry(L.prepare_and_solve, self.state, b.solve_state, -1, 1.0, 0, 0, b.timing,
                           b.clock)
        self.fused(self.state, b.solve_state, -1, 1.0, 0, 0, b.timing, b.clock)
        self.reference = self.banded = None
        if reference is not None:  # its weighted reference (the level's cost, no locks); banded
            self.reference = _direct(
                nx, plan.n_eq, ni, scale, (p.H, p.g, plan.M, plan.lo, plan.hi), self.ref_x
            )
            self.banded = _direct(
                nx, nc, ni + nl, scale, (self.Hd, self.g2, self.Mb, self.lob, self.hib), p.x,
                p.x_ref,
            )
            self.bands = entry(L.bands, self.state)
            self.bands(self.state)
        # the warm solves' kernels with their arguments in one structure (level_frame.py; the
        # back-ends are the level's for good: made here, never bound again)
        self.frame = make_level_frame(self.state, b, self.reference, self.banded)
        self.framed = entry(framed_strict, self.frame, 0, 1.0, 0)
        if reference is not None:
            self.framed_gen = entry(framed_generalized, self.frame, 1.0, 0)
        self.releasing = False  # a locked task is ramping: the level is solved in Python
        self.open = False  # some priority below 1: bands from the reference
        self.alpha = 1.0  # the level's priority (GENERALIZED)

    def flags(self) -> None:
        self.releasing = any(
            0.0 < t.ramp_factor < 1.0 and t.get_effective_weight() > 0.0
            for t in self.problem.locked
        )

    def read_priorities(self, priorities) -> None:
        """Band share per lock row (GENERALIZED; 0, strict, otherwise) and the level's alpha."""
        k, self.alpha = 0, 1.0 if not self.problem.locked else 0.0
        for t in self.problem.locked:
            m = t.rows()
            alpha = priorities.level_priority(t, self.tasks) if self.banded else 1.0
            self.keep[k: k + m] = band_share(alpha)
            self.alpha = max(self.alpha, alpha)  # the damping's share (PriorityLevels')
            k += m
        self.open = bool(np.any(self.keep > 0.0))
        self.mu_for = math.nan  # the damping's factors written again
