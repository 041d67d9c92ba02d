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
Explicit index maps between a list of joint names and a simulated robot's joint order.

PyBullet numbers joints in the order of the URDF file; Pinocchio orders sibling subtrees by joint
name. On a quadruped declared front-right, front-left, rear-right, rear-left the two orders differ,
and an array passed positionally lands on the wrong legs. A :class:`JointMap` is built once from
names (unknown or repeated names are refused) and then moves arrays both ways with one fancy index.
"""

from __future__ import annotations

import numpy as np


class JointMap:
    """Map arrays ordered like ``names`` to and from the simulator's order ``sim_names``."""

    def __init__(self, sim_names, names, model_name: str = ''):
        sim_names, names = list(sim_names), list(names)
        where = {n: i for i, n in enumerate(sim_names)}
        unknown = [n for n in names if n not in where]
        if unknown:
            raise ValueError(
                f"model '{model_name}' has no joint(s) {unknown} (joints: {sim_names})"
            )
        if len(set(names)) != len(names):
            raise ValueError(f'joint names listed twice: {names}')
        self.names = names
        self.sim_names = sim_names
        self.sim_index = np.array([where[n] for n in names], dtype=int)

    def __len__(self) -> int:
        return len(self.names)

    def to_sim(self, values, out: np.ndarray | None = None) -> np.ndarray:
        """
        Place values ordered like ``names`` into a simulator-order array.

        Into ``out`` when given (its other entries are kept), else into zeros.
        """
        x = np.asarray(values, dtype=float).reshape(-1)
        if x.size != len(self.names):
            raise ValueError(f'{x.size} values for the {len(self.names)} joints {self.names}')
        if out is None:
            out = np.zeros(len(self.sim_names))
        out[self.sim_index] = x
        return out

    def from_sim(self, sim_values) -> np.ndarray:
        """Pick the values of ``names``, in that order, from a simulator-order array."""
        return np.asarray(sim_values)[self.sim_index]
