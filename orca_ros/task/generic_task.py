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
"""Weighted least-squares task  w * || diag(s) (E x - f) ||^2  on the reduced QP variables x."""

from __future__ import annotations

import numpy as np

from ..common.task_base import TaskBase


class GenericTask(TaskBase):
    #: E selects these variables (rows = identity columns): the problem adds the task to the
    #: Hessian's diagonal instead of forming E^T E (None: a dense task)
    diagonal_columns = None
    #: of a diagonal task: a factor per column on top of weight x selection (None: all 1)
    column_weights = None

    def __init__(self, name: str):
        super().__init__(name)
        self.layout = None
        self.weight = 1.0
        self.level = 0
        # the registry of the controller holding the task (its levels depend on the task's)
        self.registry = None
        self._selection_request: np.ndarray | None = None
        self.E = np.zeros((0, 0))
        self.f = np.zeros(0)
        self.selection = np.zeros(0)
        self.selection_version = (
            0  # bumped whenever the selection changes (the plan caches weight x selection)
        )

    # -------------------------------------------------------------- configuration
    def rows(self) -> int:
        """Return the number of rows of E for the current robot (subclasses)."""
        raise NotImplementedError

    def resize(self, layout) -> None:
        self.layout = layout
        m = self.rows()
        self.E = np.zeros((m, layout.nx))
        self.f = np.zeros(m)
        self.selection = np.ones(m)
        self.selection_version += 1
        if self._selection_request is not None:
            self.set_selection_vector(self._selection_request)

    def set_weight(self, weight: float) -> None:
        weight = float(weight)
        if not (weight >= 0.0 and np.isfinite(weight)):
            raise ValueError(f"task '{self.name}': weight must be finite and >= 0, got {weight}")
        self.weight = weight

    def get_weight(self) -> float:
        return self.weight

    def get_effective_weight(self) -> float:
        """Weight times the activation ramp (what the solver uses this cycle)."""
        return self.weight * self.ramp_factor if self.is_computing() else 0.0

    def set_priority_level(self, level: int) -> None:
        if int(level) < 0:
            raise ValueError('priority level must be >= 0')
        if int(level) != self.level and self.registry is not None:
            self.registry.mark_changed()  # the levels are rebuilt at the next update
        self.level = int(level)

    def set_selection_vector(self, selection) -> None:
        s = np.asarray(selection, dtype=float).reshape(-1)
        if np.any(s < 0) or not np.all(np.isfinite(s)):
            raise ValueError(
                f"task '{self.name}': selection vector entries must be finite and >= 0"
            )
        if self.layout is None:
            self._selection_request = s
            return
        if s.shape != self.selection.shape:
            raise ValueError(
                f"task '{self.name}': selection vector needs {self.selection.size} entries, got "
                f'{s.size}'
            )
        self.selection[:] = s
        self._selection_request = s
        self.selection_version += 1

    def get_selection_vector(self) -> np.ndarray:
        return self.selection.copy()

    def get_E(self) -> np.ndarray:
        return self.E

    def get_f(self) -> np.ndarray:
        return self.f

    def residual(self, x: np.ndarray) -> np.ndarray:
        """diag(s) (E x - f) for a reduced solution x."""
        return self.selection * (self.E @ x - self.f)

    def _update(self, current_time: float, dt: float) -> None:
        self._update_affine_function(current_time, dt)

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        raise NotImplementedError

    def describe(self) -> str:
        return f'{super().describe()} weight {self.weight:g} level {self.level}'
