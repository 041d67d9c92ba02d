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
GENERALIZED resolution: continuous priorities between tasks, from weighted (0) to strict (1).

Reference: M. Liu, Y. Tan, V. Padois, "Generalized hierarchical control", Autonomous Robots
40(1):17-31,
2016. That paper blends task inputs through *generalized projectors* P(alpha) that remove a
      fraction alpha of
a lower task's action on the space of a higher task (alpha = 1: full null-space projection, strict;
alpha = 0: no projection). Formulated on one QP over per-task inputs, its alpha = 0 end is a
superposition of independently optimised tasks, not the weighted compromise, and its alpha = 1 end
is a projection, not the lexicographic optimum. This module keeps the idea (a priority value scales
how much of its influence on a higher task a lower task may exert) but builds it on our strict
cascade so that both ends are exact: alpha = 0 gives *exactly* the weighted solution, alpha = 1
*exactly* MULTI_LEVEL_WEIGHTED.

Formulation. Tasks carry levels 0..L (the order in which priorities can act); alpha[i, j] in [0, 1]
is the priority of task i over task j, for level(i) < level(j); default 1 (strict, as
MULTI_LEVEL_WEIGHTED); tasks of one level are weighted against each other. Level 0 is the weighted
QP of its tasks. Level k >= 1, given the solution x_{k-1} of the level above:

1. the *reference* x_w,k: the weighted QP of every task of levels <= k under the constraints (what
   weighting alone would do);
2. each locked task i (level < k) gets the priority alpha_i = max_j alpha[i, j] over the tasks j
   of level k; the locked rows (diag(s_i) E_i of every locked task, highest level first) are
   made orthonormal, Q (Gram-Schmidt in row order, as the strict form's locks: a row that
   depends on the rows before it is zero), and each row q of task i gets the band
   b_q = (1 - alpha_i)^2 |q . (x_w,k - x_{k-1})|: the share of the disturbance that weighting
   would inflict on task i that level k is still allowed to inflict, taken in the joint space
   of task i's rows (squared: the band closes with zero slope at alpha = 1, so that the last
   steps of a priority ramp move the solution by vanishing amounts);
3. x_k = argmin  sum_{levels <= k} w_t ||diag(s_t)(E_t x - f_t)||^2 + regularisation
         s.t. the constraints (relaxed to keep x_{k-1} feasible, see :mod:`.lower_level_problem`),
              |Q (x - x_{k-1})| <= b  (the locked tasks' rows, orthonormal).

Why orthonormal rows. With E_i = R_i Q_i (R_i triangular, Q_i orthonormal rows), the bands bound
the step z = x - x_{k-1} in the span of the locked rows by the weighted reference's own step
there, |q . z| <= (1 - alpha)^2 |q . dx_w|, whatever the conditioning of E_i: the band set is a
box of half-widths at most |dx_w| in an orthonormal frame, and it moves with alpha at the rate
2 (1 - alpha) |q . dx_w|. On the rows as they are, |diag(s) E_i z| <= b is a slab whose width in
the joint space is b / sigma along a direction of singular value sigma of E_i: where task i loses
rank (an arm stretched towards a target beyond its reach, exactly where the limits bind) the band
lets the level move the joints by b / sigma_min along directions task i barely sees, and the cost
of the upper tasks the level holds (their residuals large there) drives it to do so. That made
the solution, and the torques, steep in alpha and ill-posed: a rounding of the problem's data
moved it by as much (the compiled cycle and the Python path, the same maths summed in another
order, parted along a sweep: docs/benchmarks.md). The orthonormal frame takes sigma out of the
band's geometry. At alpha = 1 the rows span what the strict form locks (the
same Gram-Schmidt on the same rows), so the closed bands are its locks.

At alpha = 0, x_w,k satisfies every band and minimises the same cost over a larger set: x_k =
x_w,k, the weighted solution of all levels <= k (taken as such, without solving the banded form,
whose optimum sits then at a vertex of its bands and of the limits, where an ADMM solver such as
OSQP stalls). At alpha = 1 the bands close: task i is locked at x_{k-1} and the costs of the
levels above are constant, so x_k is the strict cascade's solution (computed in the null space,
as there). In between, the bands and hence the solution (the minimiser
of a strictly convex QP) move continuously with alpha, so a priority ramped in time gives
continuous torques. Cost: two QPs per level below the first when some alpha < 1 (the reference and
the banded level), one otherwise.
"""

from __future__ import annotations

import numpy as np

from .solvers import ReturnCode


def band_share(alpha: float) -> float:
    """Share of the weighted disturbance a locked task of priority alpha lets through."""
    return (1.0 - alpha) ** 2


class GeneralizedPriorities:
    """Priority values alpha[high, low] between named tasks (default 1: strict)."""

    def __init__(self):
        self._alpha: dict[tuple[str, str], float] = {}
        self.version = 0  # counts the changes (the compiled cycle re-reads them on a change)
        self.watch = None  # a Touched told of every change (the compiled cascade's)

    def set(self, high: str, low: str, value: float) -> None:  # noqa: A003 (ORCA API name)
        value = float(value)
        if not (np.isfinite(value) and 0.0 <= value <= 1.0):
            raise ValueError(f"priority of '{high}' over '{low}' must be in [0, 1], got {value}")
        self._alpha[(high, low)] = value
        self._changed()

    def get(self, high: str, low: str) -> float:
        return self._alpha.get((high, low), 1.0)

    def forget(self, name: str) -> None:
        for key in [k for k in self._alpha if name in k]:
            del self._alpha[key]
        self._changed()

    def _changed(self) -> None:
        self.version += 1
        if self.watch is not None:
            self.watch.touched = True

    def items(self):
        return self._alpha.items()

    def level_priority(self, locked_task, level_tasks) -> float:
        """
        Alpha of a locked task over a level.

        The strictest relation to any task of that level.
        """
        return max((self.get(locked_task.name, t.name) for t in level_tasks), default=1.0)

    def bands(self, problem, level_tasks, reference, x_above: np.ndarray) -> np.ndarray | None:
        """
        Per-row bands on the locked rows of ``problem`` (None when every lock is strict).

        Sets ``problem.band_rows``: the locked rows made orthonormal (the rows the bands, and the
        bands of locks being released by a ramp, bound; see LowerLevelProblem.lock); and
        ``problem.reference_x``: the reference's solution where every priority is 0 (it meets
        every band and minimises the level's cost over a larger set: the level's solution,
        without a second solve, which would look for it at a vertex of the bands, where
        ADMM solvers stall), else None.
        """
        rows = problem.orthonormal_lock_rows()
        alphas = [self.level_priority(t, level_tasks) for t in problem.locked]
        problem.reference_x = None
        if all(a >= 1.0 for a in alphas):
            return None
        reference.build()
        if reference.solve() is not ReturnCode.SUCCESS:
            return None  # no weighted reference this cycle: fall back to the strict locks
        band = np.abs(rows @ (reference.x - x_above))
        if all(band_share(a) == 1.0 for a in alphas):  # (every alpha 0: the kernel's test)
            problem.reference_x = reference.x
        k = 0
        for t, a in zip(problem.locked, alphas):
            m = t.rows()
            band[k: k + m] *= band_share(a)
            k += m
        return band
