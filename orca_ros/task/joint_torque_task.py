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
"""Joint torque task: tau = tau_des, with tau = T x + t0 recovered from the dynamics."""

from __future__ import annotations

import numpy as np

from .generic_task import GenericTask


class JointTorqueTask(GenericTask):
    def __init__(self, name: str):
        super().__init__(name)
        self._tau_des: np.ndarray | None = None

    def rows(self) -> int:
        return self.layout.ndof

    def set_desired(self, torque) -> None:
        t = np.asarray(torque, dtype=float).reshape(-1)
        if self.robot is not None and t.size != self.robot.get_nr_of_degrees_of_freedom():
            raise ValueError(
                f"task '{self.name}': desired torque needs "
                f'{self.robot.get_nr_of_degrees_of_freedom()} values, got {t.size}'
            )
        if not np.all(np.isfinite(t)):
            raise ValueError(f"task '{self.name}': desired torque contains NaN/inf")
        self._tau_des = t.copy()

    def get_desired(self) -> np.ndarray:
        return np.zeros(self.layout.ndof) if self._tau_des is None else self._tau_des.copy()

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        lay = self.layout
        self.E[:] = lay.T
        if self._tau_des is None:
            np.negative(lay.t0, out=self.f)
        else:
            np.subtract(self._tau_des, lay.t0, out=self.f)
