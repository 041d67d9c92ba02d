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
The levels below the first by kernel: ``PriorityLevels.solve`` without its Python layers.

Made by the compiled cycle when its first level is solved by kernel and DAQP solves the levels
below (MULTI_LEVEL_WEIGHTED and GENERALIZED): per level (:mod:`.cascade_level`), one kernel
writes its problem (:mod:`.lower_level`) and, strict, solves it by DAQP's C solve
(:mod:`.direct_daqp`) in the same call. A GENERALIZED level with a priority below 1 solves its
weighted reference, then its banded form (:func:`.lower_level.bands`), each by kernel. A level
whose locks are being released by a ramp (a locked task ramping in or out: the banded form of
``LowerLevelProblem.lock``) is solved by its own Python objects that cycle, as on the reference
path. A level that fails is dropped for the cycle, said in the debug log, as there.

In the controller's lean cycle, :mod:`.cascade_step` runs these kernels in the same call as the
first level; :meth:`CompiledCascade.solve` takes over where it stops (``start``, ``resumed``).
"""

from __future__ import annotations

import math

import numpy as np

from . import lower_level as L
from .cascade_level import Level
from ..solvers import clock, daqp_c, direct_daqp, ReturnCode
from ...common.watched import Touched
from ...utils.logger import get_logger

_LOG = get_logger('optim')
_SUCCESS = ReturnCode.SUCCESS
_NOTHING = object()  # a level without weighted tasks this cycle
_STRICT = object()  # a level whose locks are all strict this cycle
_NO_DEADLINE = float('inf')  # (a kernel's deadline)
_UPDATE_ALL = daqp_c.UPDATE_ALL
_DEFAULT_CAP = direct_daqp.DirectDAQPBackend.default_max_iterations


def unlowered_reason(levels) -> str | None:
    """Why the levels below the first cannot be solved by kernel (None: they can)."""
    why = clock.unavailable_reason()  # (their kernels time their solves)
    if why is not None:
        return why
    for p in levels.problems[1:]:
        if p.null_space is not None:
            return 'a solver other than DAQP'
        for t in p.locked:
            cols = t.diagonal_columns
            if cols is None:
                continue
            expected = np.zeros_like(t.E)
            expected[np.arange(t.rows()), np.arange(cols.start, cols.stop)] = 1.0
            if not np.array_equal(t.E, expected):
                return f"task '{t.name}' selects its variables with other than ones"
    return None


def _budget(back, deadline, max_iterations):
    """Give a back-end this cycle's deadline and iteration cap; return it."""
    back.deadline = deadline
    back.max_iterations = max_iterations or back.default_max_iterations
    return back


class CompiledCascade:
    def __init__(self, cycle, levels, priorities):
        self.cycle, self.levels, self.priorities = cycle, levels, priorities
        plan, asm = cycle.plan, cycle.assembly
        self.lower = [Level(plan, asm, levels, i) for i in range(1, len(levels.problems))]
        self._version = None  # of the priorities last read
        # set where the Python here ran (a full pass's flags, a solve) and by any change of the
        # priorities or the lower levels' damping: cascade_step's modes to write again
        self.changed = Touched()
        priorities.watch = levels.watch = self.changed

    def read_priorities(self) -> None:
        """Read each level's band shares and alpha where the priorities changed."""
        if self.priorities.version != self._version:
            for lev in self.lower:
                lev.read_priorities(self.priorities)
            self._version = self.priorities.version

    def flags(self) -> None:
        """After the objects' steps of a full pass: which levels release locks this cycle."""
        self.changed.touched = True
        for lev in self.lower:
            lev.flags()

    def solve(self, deadline, max_iterations, name: str, solved=None, start: int = 0,
              resumed=None):
        """
        Solve every level in priority order, as ``PriorityLevels.solve`` returns.

        ``solved``: the first level's problem when it is solved already (the one-call cycle);
        ``start``: the first level below to solve (the levels before it solved by
        :mod:`.cascade_step`), ``resumed``: that kernel's outcome for it (its row of ``res``).
        """
        self.changed.touched = True
        if solved is None:
            solved, code, dropped = self.cycle.solve_first(self.levels, deadline, max_iterations)
            if code is not _SUCCESS:
                return solved, code, dropped
        self.read_priorities()
        late = _NO_DEADLINE if deadline is None else deadline  # (the kernels')
        most = max_iterations or _DEFAULT_CAP
        lower = self.lower
        for i in range(start, len(lower)):
            lev = lower[i]
            p = lev.problem
            b = p.locked_backend
            if resumed is not None:  # where cascade_step stopped: its outcome for the level
                code = self._resumed(lev, resumed, deadline, max_iterations)
                resumed = None
            elif not (lev.releasing or lev.open) and b.warm \
                    and p.temporal_damping == lev.mu_for:
                # the steady strict level: prepared and solved warm in one call (_by_kernel's
                # and solve_prepared's, inline: their Python frames spared at every level)
                b.deadline, b.max_iterations = deadline, most
                flag, iters, cap, ns = lev.framed(lev.frame, _UPDATE_ALL, late, most)
                if flag == 1:  # (the time model updated by the kernel)
                    self.strict_solved(lev, iters)
                    solved = p
                    continue
                code = self._settle(lev, b.prepared_failed(flag, iters, cap, ns, L.PREPARED))
            else:
                code = self._releasing(lev, solved.x, deadline, max_iterations) \
                    if lev.releasing else None
                if code is None or code is _STRICT:
                    code = self._by_kernel(lev, deadline, max_iterations, code is None)
            if code is _NOTHING:  # nothing to optimise here: the solution above stands,
                np.copyto(lev.problem.x, solved.x)  # as the level's, which the next locks to
                lev.problem.prev_ok[0] = 0  # (no solution of its own to damp towards next)
                continue
            if code is not _SUCCESS:
                _LOG.debug(
                    "controller '%s': level %d not solved (%s), keeping level %d's solution",
                    name, lev.problem.level, code.value, solved.level,
                )
                return solved, _SUCCESS, True
            solved = lev.problem
        return solved, _SUCCESS, False

    # ------------------------------------------------------------------ with cascade_step
    @staticmethod
    def strict_solved(lev, iters) -> None:
        """Take a strict level's warm solve by kernel (its x written): SUCCESS."""
        p = lev.problem
        p.locked_backend.iterations = iters
        p.band = None
        if not p.prev_ok[0] and p.temporal_damping > 0.0:
            p.prev_ok[0] = 1
        p.return_code = _SUCCESS

    @staticmethod
    def generalized_solved(lev, it_ref, it, stage) -> None:
        """Take a GENERALIZED level's solves by kernel (its x written): SUCCESS."""
        p = lev.problem
        lev.reference.iterations = it_ref
        banded = stage == L.S_BANDED
        (lev.banded if banded else p.locked_backend).iterations = it
        p.band = lev.band if banded else None
        if not p.prev_ok[0] and p.temporal_damping > 0.0:
            p.prev_ok[0] = 1
        p.return_code = _SUCCESS

    def _resumed(self, lev, row, deadline, max_iterations):
        """Return a level's code from the outcome ``row`` cascade_step stopped at (a failure)."""
        f, it_ref, it, stage, cap, ns = row.tolist()
        p = lev.problem
        if lev.open:  # as _by_kernel and _generalized after their kernel call
            p.band = None
            code = self._generalized_took(lev, deadline, max_iterations, f, it_ref, it, stage,
                                          cap, ns)
            return self._settle(lev, code, fallback=False)
        b = _budget(p.locked_backend, deadline, max_iterations)
        return self._settle(lev, b.prepared_failed(f, it, cap, ns, L.PREPARED))

    @staticmethod
    def _by_kernel(lev, deadline, max_iterations, banded: bool):
        """
        Solve the level by kernel: prepared and solved in one call (strict), or by its bands.

        ``banded`` False: strict whatever the priorities (the reference path found no band).
        """
        p = lev.problem
        mu = p.temporal_damping
        if mu != lev.mu_for:  # (numpy item writes are not free: on a change only)
            # times the own and the upper tasks' weights, by kernel (PriorityLevels.damping_scale)
            alpha = lev.alpha
            lev.mu[0] = mu * alpha
            lev.mu[1] = mu * alpha * math.sqrt(1.0 - alpha)
            lev.mu_for = mu
        p.band = None
        if banded and lev.open:
            code = CompiledCascade._generalized(lev, deadline, max_iterations)
        else:
            b = _budget(p.locked_backend, deadline, max_iterations)
            return CompiledCascade._settle(lev, b.solve_prepared(lev.fused, lev.state,
                                                                 L.PREPARED))
        return CompiledCascade._settle(lev, code, fallback=False)

    @staticmethod
    def _settle(lev, code, fallback: bool = True):
        """
        Finish a level's solve that returned ``code`` (solve_prepared's).

        ``fallback``: a strict solve that failed is retried in the null space of its locks
        (as _solve_locked_stacked).
        """
        p = lev.problem
        if fallback and code.__class__ is not int and code is not _SUCCESS:
            code, z = p.solve_stacked_in_null_space(lev.Hd, lev.g2)
            if code is _SUCCESS:
                np.add(p.x_ref, z, out=p.x)
        if code.__class__ is int:  # not prepared
            if code == L.PREPARED - L.NOTHING_TO_DO:
                return _NOTHING
            code = ReturnCode.NON_FINITE_PROBLEM
        elif p.temporal_damping > 0.0:  # after a failure, the next solve is damped towards x_ref
            p.prev_ok[0] = code is _SUCCESS
        p.return_code = code
        return code

    @staticmethod
    def _generalized(lev, deadline, max_iterations):
        """
        Solve a GENERALIZED level: its weighted reference, then its banded form.

        The strict form when the reference fails or leaves no band open (as
        ``GeneralizedPriorities.bands`` returns None then). One kernel call when every solve is
        warm (the time model of the reference's back-end takes the call's time and
        iterations); else, from the solve that did not run warm, one solve at a time.
        """
        ref = _budget(lev.reference, deadline, max_iterations)
        flag, it_ref, it, stage, cap, ns = lev.framed_gen(
            lev.frame, _NO_DEADLINE if deadline is None else deadline, ref.max_iterations)
        return CompiledCascade._generalized_took(lev, deadline, max_iterations, flag, it_ref, it,
                                                 stage, cap, ns)

    @staticmethod
    def _generalized_took(lev, deadline, max_iterations, flag, it_ref, it, stage, cap, ns):
        """Return a GENERALIZED level's code from its kernel's outcome (see _generalized)."""
        p = lev.problem
        ref = _budget(lev.reference, deadline, max_iterations)
        banded, strict = lev.banded, p.locked_backend
        if stage == L.S_BANDED:
            p.band = lev.band
        if flag > 0:  # the last solve succeeded (the time model updated by the kernel)
            ref.iterations = it_ref
            (banded if stage == L.S_BANDED else strict).iterations = it
            return _SUCCESS
        if stage == L.S_PREPARED:
            return flag
        if stage == L.S_REFERENCE:  # one solve at a time from the reference
            if flag == 0:
                code = ref.solve_bound()  # set up, cold
            else:
                code = ref.ran(flag, it_ref, ns * 1e-9)
                if code is not _SUCCESS and it_ref < cap:
                    code = ref.solve_cold(cap - it_ref)  # once more, cold
            if code is _SUCCESS and lev.bands(lev.state):
                p.band = lev.band
                if L.weighted(lev.state):  # the reference is the solution (as the kernel's)
                    np.copyto(p.x, lev.ref_x)
                    return _SUCCESS
                return _budget(banded, deadline, max_iterations).solve_bound()
            return _budget(strict, deadline, max_iterations).solve_bound()
        back = _budget(banded if stage == L.S_BANDED else strict, deadline, max_iterations)
        ref.iterations = it_ref
        if flag == 0:
            return back.solve_bound()  # set up, cold
        code = back.ran(flag, it, ns * 1e-9)
        if code is not _SUCCESS and it < cap:
            code = back.solve_cold(cap - it)  # once more, cold
        return code

    def _releasing(self, lev, x_above, deadline, max_iterations):
        """
        Solve a level, with a lock being released, by its Python objects (the banded form).

        _STRICT when no band is left (the kernel's strict form solves it).
        """
        levels, i = self.levels, lev.index
        p, tasks, ref = levels.problems[i], levels.level_tasks[i], levels.references[i]
        if not any(t.get_effective_weight() > 0.0 for t in tasks):
            return _NOTHING
        band = None
        if ref is not None:
            ref.set_budget(deadline, max_iterations)
            band = self.priorities.bands(p, tasks, ref, x_above)
        p.lock(x_above, band)
        if p.band is None:
            return _STRICT
        p.damping_scale = levels.damping_scale(i, self.priorities)
        p.build()
        p.set_budget(deadline, max_iterations)
        return p.solve()
