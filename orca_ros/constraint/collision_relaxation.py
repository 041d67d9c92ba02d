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
The collision rows' smoothness: bounds that relax, rows that relax away instead of vanishing.

A mixin of :class:`~.collision_avoidance.CollisionAvoidanceConstraint` (its arrays: ``C``, ``lb``,
``settings``, the pairs written ``_sel`` / ``_seld`` / ``_written``, the last cycle's rows): each
pair's last bound and the cycle it was set in, kept across obstacles coming and going; the rows of
removed obstacles (``_leave``) and of pairs that left the rows (``hold_departed``), their bounds
relaxing at max_deceleration / horizon per second until they let go. The compiled cycle's kernels
(``constraint/collision_kernel.py``) do the same on the same arrays.
"""

from __future__ import annotations

import numpy as np

#: a row is let go once its bound lets the bodies close in at LET_GO times max_deceleration
LET_GO = 10.0


class RowRelaxation:
    def kept_bounds(self):
        """
        Return each pair's last bound, the cycle it was set in, its floor, the cycle's count.

        (Arrays.) The floor is the least distance the pair is held at (see
        :meth:`~.collision_avoidance.CollisionAvoidanceConstraint.floor_of`).

        A bound relaxes from its last value at A / horizon per second at most. The pairs are
        renumbered when obstacles come and go: what was kept follows each pair by its bodies'
        names (else the arm's own pairs would lose theirs when a ball is removed, and the torques
        step in one cycle: test_ros_obstacles.py).
        """
        geom = self.geometry
        if self._kept_version != geom.version:
            names = [geom.names_of(k) for k in range(len(geom.pairs))]
            size = max(1, len(names))
            kept, when, floor = np.zeros(size), np.full(size, -2, np.int64), np.zeros(size)
            if self._kept_version is not None:
                old = {n: k for k, n in enumerate(self._kept_names)}
                for k, n in enumerate(names):
                    if n in old:
                        kept[k], when[k] = self._kept[old[n]], self._kept_cycle[old[n]]
                        floor[k] = self._floor[old[n]]
                new = {n: k for k, n in enumerate(names)}  # the last rows' pairs too (-1: gone)
                for i in range(int(self._written[0])):
                    if self._sel[i] >= 0:
                        self._sel[i] = new.get(self._kept_names[self._sel[i]], -1)
            self._kept, self._kept_cycle, self._kept_names = kept, when, names
            self._floor = floor
            self._kept_version = geom.version
        return self._kept, self._kept_cycle, self._floor, self._cycle

    def _rate_limited(self, i, bound, kept, room, vel, drift, dt, h, m) -> float:
        """
        Return row i's bound, its last one ``kept`` (last cycle's) moved at A / h per second.

        It relaxes at that rate at most (never past its cap A - drift), and the braking margin's
        term tightens it at that rate at most: near the limit at a closing speed v that term's
        slope in the distance is A / (h v / 2), and a pair creeping onto the safety distance
        would see it engage in one cycle. What viability and the horizon ask applies at once
        (the bounds without the margin's term, computed for the m rows when first needed).
        """
        relax = self.max_deceleration / h * dt
        if bound > kept + relax:
            if self._cycle_safe is None:
                out = self._bound.upper(room, vel, dt, h, self._out_safe, one_step=False,
                                        margin=False)
                self._cycle_safe = -out[:m] - drift
            bound = max(self._cycle_safe[i], kept + relax)
        if bound < kept - relax:
            bound = min(kept - relax, self.max_deceleration - drift[i])
        return bound

    def _leave(self, m: int, dt: float) -> None:
        """
        Write the rows of removed obstacles after the ``m`` rows of this cycle's pairs.

        Each is the row its pair had last, its bound relaxed at A / horizon per second until it
        lets the bodies close in at LET_GO A (a task pulling hard into the place may still meet a
        bound below -A: dropped there, it let the torques step), or room runs out.
        """
        relax = self.max_deceleration / max(self.horizon, dt) * dt
        keep = []
        for row, bound in self._leaving:
            bound -= relax
            if bound > self.settings[4] and m < self.max_pairs:
                self.C[m], self.lb[m] = row, bound
                m += 1
                keep.append((row, bound))
        self._leaving = keep

    def hold_departed(self, m: int, dt: float) -> int:
        """
        Write, after the ``m`` rows of this cycle, those of the pairs that had one and left.

        Each keeps the row it had last, its bound relaxing at A / horizon per second, until it
        lets the bodies close in at LET_GO A, or room runs out; return the rows' count. A pair
        leaves with a bound that still binds when an obstacle moves off at once (a sparse pose,
        a detection corrected) or the arm is pushed off one that came too close: dropped at
        once, the row let the torques jump in one cycle (test_obstacle_updates.py).
        Its last row, not the pair's row now: an obstacle that jumped has another normal.
        """
        relax = self.max_deceleration / max(self.horizon, dt) * dt
        kept, when, cycle = self._kept, self._kept_cycle, self._cycle[0]
        for i in range(self._last_m):
            k = int(self._last_sel[i])
            if k < 0 or when[k] != cycle - 1:
                continue  # its pair gone (an obstacle removed: _leave), or it has its row
            bound = kept[k] - relax
            if bound > self.settings[4] and m < self.max_pairs:
                self.C[m, self.layout.acc], self.lb[m] = self._lastC[i], bound
                kept[k], when[k] = bound, cycle
                self._sel[m], self._seld[m] = k, self._last_seld[i]
                m += 1
        return m
