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
The whole cycle of a stack of levels in one kernel call: the one-call cycle, then every level.

With levels below the first, a cycle was the one-call cycle (:mod:`.fused_step`), then one
kernel call per level (:mod:`.cascade`) with its Python around it, then one more to write the
last level's solution out: on the lwr's three levels, the calls and the Python cost about as much
per cycle as a level's kernel. Here :func:`cascade_step` runs the first level, each level below
whose kernels run warm (its ``mode``: strict, or GENERALIZED with bands; 0: Python's this cycle),
as the cascade's own kernels do, and writes the last solution out. It stops at the
first level it cannot finish: one not warm, or a solve that failed; the cascade takes over
from there with the kernel's outcome for that level (:meth:`.cascade.CompiledCascade.solve`),
so a failure is handled as before (retried cold, the null-space fallback, the level dropped).
"""

from __future__ import annotations

from numba import typeof
from numba.experimental import structref
import numpy as np

from . import lower_level as L
from .cycle_kernel import finish, step
from .level_frame import framed_generalized, framed_strict
from ..solvers.daqp_c import UPDATE_ALL
from ...utils.jit import entry, njit
from ...utils.struct_type import StructType

#: a level's mode: Python's this cycle, strict warm, GENERALIZED warm
PYTHON, STRICT, GENERALIZED = range(3)
#: a row of ``res``: flag, the reference's iterations, iterations, stage, cap, nanoseconds
#: (the first level's row: its flag, iterations, cap, nanoseconds, run's flags)
FLAG, IT_REF, IT, STAGE, CAP, NS = range(6)
_NOTHING = L.PREPARED - L.NOTHING_TO_DO

#: the one-call cycle's frame, the levels' frames (a tuple), their modes, whether each is damped
#: in time (its solution kept for the next cycle's damping), the outcomes
FIELDS = ('fr', 'levels', 'mode', 'damped', 'res')


@structref.register
class CascadeFrameType(StructType):
    """Its fields' types: see struct_type."""


class CascadeFrame(structref.StructRefProxy):
    """What :func:`cascade_step` reads besides the cycle's time (fields: :data:`FIELDS`)."""


structref.define_proxy(CascadeFrame, CascadeFrameType, list(FIELDS))


@njit
def _construct(*fields):
    return CascadeFrame(*fields)


@njit
def cascade_step(cf, dt, deadline, most):
    """
    Run the first level (:func:`.cycle_kernel.step`), then the levels below while they run warm.

    Returns (run's flags, k, the first level's iterations): k levels solved (0: the first
    failed; len(levels) + 1: all, the last solution written out). ``res`` holds the outcome
    of each level run, the one that stopped it included (its FLAG not a success; PYTHON
    mode: not run, FLAG 0).
    """
    fr, res, mode, levels, damped = cf.fr, cf.res, cf.mode, cf.levels, cf.damped
    flags, flag, iters, cap, ns = step(fr.ws, fr.s, dt, deadline, most, fr.least, fr.timing,
                                       fr.clock, 0, fr.x_out, fr.acc_out, fr.tau, fr.tau_cmd)
    res[0, 0], res[0, 1], res[0, 2], res[0, 3] = flag, iters, cap, ns
    if flag != 1:
        return flags, 0, iters
    x = fr.s.x
    for i in range(len(levels)):
        lf, row = levels[i], i + 1
        m = mode[i]
        res[row, FLAG] = 0
        if m == STRICT:
            f, it, cp, n = framed_strict(lf, UPDATE_ALL, deadline, most)
            ok = f == 1
            res[row, FLAG], res[row, IT_REF], res[row, IT] = f, 0, it
            res[row, STAGE], res[row, CAP], res[row, NS] = L.S_STRICT, cp, n
        elif m == GENERALIZED:
            f, ir, it, stage, cp, n = framed_generalized(lf, deadline, most)
            ok = f > 0
            res[row, FLAG], res[row, IT_REF], res[row, IT] = f, ir, it
            res[row, STAGE], res[row, CAP], res[row, NS] = stage, cp, n
        else:
            return flags, row, iters
        s = lf.s
        if f == _NOTHING:  # nothing to optimise: the solution above stands (the cascade's)
            for a in range(x.shape[0]):
                s.x[a] = x[a]
            s.prev_ok[0] = 0
        elif not ok:
            return flags, row, iters
        elif damped[i]:  # (damped towards it next cycle)
            s.prev_ok[0] = 1
        x = s.x
    finish(fr.ws, x, fr.x_out, fr.acc_out, fr.tau, fr.tau_cmd)
    return flags, len(levels) + 1, iters


class CascadeStep:
    """The one-kernel cycle of a FusedStep and a CompiledCascade (None where it does not fit)."""

    @classmethod
    def make(cls, fused, cascade):
        """Return the step, or None where the levels' frames are not of one type."""
        kinds = {typeof(lev.frame) for lev in cascade.lower}
        if fused is None or cascade is None or len(kinds) != 1:
            return None
        return cls(fused, cascade)

    def __init__(self, fused, cascade):
        self.fused, self.cascade = fused, cascade
        n = len(cascade.lower)
        self.n = n
        self.mode = np.zeros(n, dtype=np.int64)
        self.damped = np.zeros(n, dtype=np.int64)
        self.res = np.zeros((n + 1, 6), dtype=np.int64)
        # set when the modes are to be written again: the cascade's Python ran since (the
        # levels' states taken in full), the priorities or the lower levels' damping changed
        self.changed = cascade.changed
        self.bind()

    def bind(self) -> None:
        """Compile (or load) the kernel for the frames' types."""
        levels = tuple(lev.frame for lev in self.cascade.lower)
        self.frame = _construct(self.fused.frame, levels, self.mode, self.damped, self.res)
        self.run = entry(cascade_step, self.frame, 1e-3, 1.0, 1)

    def write_modes(self) -> None:
        """
        Each level's mode this cycle (as the cascade's solve would pick its path).

        A cycle runs (the controller's lean cycle, inline): where :attr:`changed` is set, this
        (which clears it); then :attr:`run`. A steady cycle (not changed, every level solved by
        the kernel: ``k > n``) is the controller's success, as the one-call cycle's of one
        level: the levels' Python states are left as the last full cycle wrote them (SUCCESS,
        their band), only the kernel's arrays change (their solutions, iteration counts in
        ``res``). Any other cycle goes on with :meth:`took`.
        """
        casc, mode, damped = self.cascade, self.mode, self.damped
        self.changed.touched = False
        casc.read_priorities()
        for i, lev in enumerate(casc.lower):
            p = lev.problem
            if lev.releasing or p.temporal_damping != lev.mu_for:
                m = PYTHON
            elif lev.open:
                m = GENERALIZED
            else:
                m = STRICT if p.locked_backend.warm else PYTHON
            mode[i] = m
            damped[i] = p.temporal_damping > 0.0

    def took(self, flags, k: int, iters: int, deadline, most: int, max_iterations, name: str,
             levels):
        """
        Take the kernel's outcome (``run``'s), then what it left, as ``CompiledCycle.solve``.

        True when every level solved in the kernel: the solution written out (the controller's
        success). Not for a steady cycle's success (see :meth:`write_modes`).
        """
        casc, fused = self.cascade, self.fused
        if k == 0:  # the first level did not solve warm: its failure handled as the cycle's
            casc.changed.touched = True  # (the levels' states: this cycle's, not the last's)
            fused.backend.deadline, fused.backend.max_iterations = deadline, most
            f, it, cap, ns = self.res[0, :4].tolist()
            first = fused.took(flags, f, it, cap, ns)
            return fused.cycle.solve(levels, deadline, max_iterations, name, first)
        fused.took_solved(flags, iters)
        levels.contacts_relaxed = False
        solved = self._took(k - 1)
        if k > self.n:
            return True
        ran = self.mode[k - 1] != PYTHON  # (else not run: the cascade's as any cycle)
        return casc.solve(deadline, max_iterations, name, solved, k - 1,
                          self.res[k] if ran else None)

    def _took(self, n: int):
        """Take the kernel's outcome for the first ``n`` levels below (solved); the last one."""
        casc, res, mode = self.cascade, self.res, self.mode
        solved = casc.levels.problems[0]
        for i in range(n):
            lev = casc.lower[i]
            f, it_ref, it, stage = res[i + 1, :4].tolist()
            if f == _NOTHING:  # the solution above stands (its x: written by the kernel)
                continue
            if mode[i] == STRICT:
                casc.strict_solved(lev, it)
            else:
                casc.generalized_solved(lev, it_ref, it, stage)
            solved = lev.problem
        return solved
