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
Joints the controller does not command, held at their measured positions in the model.

An arm with a gripper: the arm's controller commands the arm joints and leaves the fingers to the
gripper's driver. The fingers still move the arm's dynamics and the frames beyond them (a tool
centre point between the fingers), so they are not dropped from the model: they are welded at the
position the joint states report, with Pinocchio's ``buildReducedModel``. When a locked joint has
moved by more than a tolerance since the last weld, the model is welded again at the new position
(a rebuild of the model, not free: it only happens while the gripper moves). The reduced model
keeps the joint and frame structure across welds, so frame ids and vector sizes never change.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin


class LockedJoints:
    """The welding of named joints of a full model at given positions."""

    def __init__(self, full_model: pin.Model, names, tolerance: float = 1e-4):
        names = list(names)
        if len(set(names)) != len(names):
            raise ValueError(f'locked joints listed twice: {names}')
        if not tolerance >= 0:
            raise ValueError(f'locked joint tolerance must be >= 0, got {tolerance}')
        self.full_model = full_model
        self.names = names
        self.tolerance = float(tolerance)
        self.ids = []
        for n in names:
            if not full_model.existJointName(n):
                known = [full_model.names[j] for j in range(1, full_model.njoints)]
                raise ValueError(f"cannot lock joint '{n}': the robot has joints {known}")
            jid = full_model.getJointId(n)
            jm = full_model.joints[jid]
            if jm.nv != 1 or jm.nq not in (1, 2):
                raise ValueError(
                    f"cannot lock joint '{n}' of type {jm.shortname()}: "
                    'only 1-DoF joints are locked'
                )
            self.ids.append(jid)
        lo = np.array([full_model.lowerPositionLimit[full_model.joints[j].idx_q]
                       if full_model.joints[j].nq == 1 else -np.inf for j in self.ids])
        hi = np.array([full_model.upperPositionLimit[full_model.joints[j].idx_q]
                       if full_model.joints[j].nq == 1 else np.inf for j in self.ids])
        lo[lo < -1e10] = -np.inf
        hi[hi > 1e10] = np.inf
        self.lower, self.upper = lo, hi
        # until a measurement comes: zero, or the nearest limit when zero is outside them
        self.positions = np.clip(np.zeros(len(names)), lo, hi)

    def reduced_model(self, positions=None) -> pin.Model:
        """Weld the locked joints at ``positions`` (their order; default: the last ones)."""
        if positions is not None:
            self.positions = self.checked(positions)
        q = pin.neutral(self.full_model)
        for jid, x in zip(self.ids, self.positions):
            jm = self.full_model.joints[jid]
            if jm.nq == 1:
                q[jm.idx_q] = x
            else:  # continuous joint: (cos, sin)
                q[jm.idx_q], q[jm.idx_q + 1] = math.cos(x), math.sin(x)
        return pin.buildReducedModel(self.full_model, self.ids, q)

    def checked(self, positions) -> np.ndarray:
        x = np.asarray(positions, dtype=float).reshape(-1)
        if x.size != len(self.names):
            raise ValueError(
                f'locked joint positions: {x.size} values for the {len(self.names)} locked '
                f'joints {self.names}'
            )
        if not np.isfinite(x).all():
            raise ValueError(f'locked joint positions contain NaN or infinite values: {x}')
        return x

    def moved(self, positions) -> bool:
        """Whether ``positions`` differ from the welded ones by more than the tolerance."""
        return bool(np.any(np.abs(positions - self.positions) > self.tolerance))
