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
Linear constraints  lb <= C x <= ub  on the reduced QP variables x.

``kind`` tells the problem how to route the rows: "equality" (lb == ub, solver equality rows),
"inequality" (general rows) or "box" (bounds on the joint-acceleration variables, merged with every
other box constraint into the solver's variable bounds). An inactive constraint keeps its rows (the
solver's sparsity pattern never changes) but they are relaxed: zero rows for equalities, infinite
bounds otherwise.
"""

from __future__ import annotations

import numpy as np

from ..common.task_base import TaskBase


def _limit_vector(values, n: int, what: str, name: str) -> np.ndarray:
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size == 1:
        v = np.full(n, float(v[0]))
    if v.shape != (n,):
        raise ValueError(f"constraint '{name}': {what} needs {n} values, got {v.size}")
    if np.any(np.isnan(v)):
        raise ValueError(f"constraint '{name}': {what} contains NaN")
    return v


class GenericConstraint(TaskBase):
    kind = 'inequality'

    def __init__(self, name: str):
        super().__init__(name)
        self.layout = None
        self.C = np.zeros((0, 0))
        self.lb = np.zeros(0)
        self.ub = np.zeros(0)

    def rows(self) -> int:
        raise NotImplementedError

    def resize(self, layout) -> None:
        self.layout = layout
        m = self.rows()
        self.C = np.zeros((m, layout.nx))
        self.lb = np.full(m, -np.inf)
        self.ub = np.full(m, np.inf)

    def get_C(self) -> np.ndarray:
        return self.C

    def get_lower_bound(self) -> np.ndarray:
        return self.lb

    def get_upper_bound(self) -> np.ndarray:
        return self.ub

    def violation(self, x: np.ndarray) -> float:
        """Largest violation of lb <= C x <= ub at x (0 when satisfied)."""
        if self.kind == 'box':
            y = x[self.layout.joint_acc]
        else:
            y = self.C @ x
        return float(max(0.0, np.max(self.lb - y, initial=0.0), np.max(y - self.ub, initial=0.0)))

    def _update(self, current_time: float, dt: float) -> None:
        self._update_constraint_function(current_time, dt)

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        raise NotImplementedError


class JointBoxConstraint(GenericConstraint):
    """
    Bounds on the joint accelerations (C = [0 I 0] implicitly): lb <= q_ddot <= ub.

    ``hard`` boxes (acceleration limits) win over soft ones (kinematic predictions of position and
    velocity limits) when their bounds are incompatible.
    """

    kind = 'box'
    hard = False

    def rows(self) -> int:
        return self.layout.ndof

    def resize(self, layout) -> None:
        super().resize(layout)
        self.C = np.zeros((0, layout.nx))  # never used: the problem takes lb/ub as variable bounds
