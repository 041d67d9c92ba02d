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
Frame kinematics of a :class:`~orca_ros.robot.robot_model.RobotModel`, in the world and the base.

World-aligned terms (pose, Jacobian [linear; angular], velocity, classical bias acceleration) come
from Pinocchio's Data of the current state and are cached per frame and state; the base-frame and
frame-to-frame forms are derived from them (:mod:`.frame_kinematics`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from . import frame_kinematics as fk

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class FrameApiMixin:
    def set_base_frame(self, frame: str) -> None:
        """Set the frame poses, Jacobians and accelerations are expressed in (world: inertial)."""
        self._require_model()
        fid = self.get_frame_id(frame)
        self._base_frame = frame
        self._base_fid = fid
        # a frame rigidly attached to the world never moves: its transform is constant
        self._base_static = (not self.floating_base) and (
            fid < 0 or self.model.frames[fid].parentJoint == 0
        )
        self._base_is_world = fid < 0 or (
            self._base_static and self._frame_world_pose_static(fid) is None
        )
        self._base_static_T = (
            None
            if self._base_is_world
            else (self._frame_world_pose_static(fid) if self._base_static else None)
        )
        self._frame_cache.clear()

    def _frame_world_pose_static(self, fid: int):
        """
        World pose of a frame attached to the universe joint.

        Or None when it is the identity.
        """
        T = self.model.frames[fid].placement.homogeneous
        return None if np.allclose(T, np.eye(4)) else T

    def get_base_frame(self) -> str:
        return self._base_frame

    def world_frame_terms(self, fid: int):
        """
        (world_H_frame, J, velocity, bias acceleration) of frame ``fid`` in world axes.

        Cached per state.
        """
        hit = self._frame_cache.get(fid)
        stamp = self.buffers.stamp
        if hit is not None and hit[0] == stamp:
            return hit[1]
        self.update_terms()
        m, d = self.model, self.data
        T = pin.updateFramePlacement(m, d, fid).homogeneous
        J = pin.getFrameJacobian(m, d, fid, _LWA)
        vel = pin.getFrameVelocity(m, d, fid, _LWA).vector
        acc = pin.getFrameClassicalAcceleration(m, d, fid, _LWA).vector
        # Pinocchio spatial vectors are [linear; angular], as our Jacobians
        terms = (T, J, vel, acc)
        self._frame_cache[fid] = (stamp, terms)
        return terms

    def world_frame_placement(self, fid: int):
        """
        world_H_frame (4x4) of frame ``fid``: the placement of :meth:`world_frame_terms` alone.

        Its Jacobian and velocities are not computed (a support polygon needs the feet's places
        only).
        """
        hit = self._frame_cache.get(fid)
        if hit is not None and hit[0] == self.buffers.stamp:
            return hit[1][0]
        self.update_terms()
        return pin.updateFramePlacement(self.model, self.data, fid).homogeneous

    def static_base_placement(self):
        """
        world_H_base (4x4) of a base frame that never moves; None where it moves.

        The identity for the world frame; a frame fixed to the world (a fixed base's root link,
        a frame on it) keeps its placement in the model.
        """
        if self._base_is_world:
            return np.eye(4)
        return self._base_static_T if self._base_static else None

    def _base_terms(self):
        if self._base_is_world:
            return None
        if self._base_static:
            return self._base_static_T, None, None, None
        return self.world_frame_terms(self._base_fid)

    def frame_terms(self, frame_id: int):
        """
        Return the kinematics of a frame in the base frame.

        (pose 4x4, Jacobian 6xnv, velocity 6, bias acceleration 6).
        """
        tip = self.world_frame_terms(frame_id)
        base = self._base_terms()
        if base is None:
            return tip
        Tb, Jb, vb, ab = base
        Tf, Jf, vf, af = tip
        if Jb is None:  # static base: pure rotation/translation of constant frame
            Rbt = Tb[:3, :3].T
            pose = fk.relative_pose(Tb, Tf)
            J = np.vstack((Rbt @ Jf[:3], Rbt @ Jf[3:]))
            return (
                pose,
                J,
                np.concatenate((Rbt @ vf[:3], Rbt @ vf[3:])),
                np.concatenate((Rbt @ af[:3], Rbt @ af[3:])),
            )
        return (
            fk.relative_pose(Tb, Tf),
            fk.relative_jacobian(Tb, Jb, Tf, Jf),
            fk.relative_velocity(Tb, vb, Tf, vf),
            fk.relative_bias_acceleration(Tb, vb, ab, Tf, vf, af),
        )

    def get_frame_pose(self, frame: str) -> np.ndarray:
        """4x4 pose of ``frame`` in the base frame."""
        return self.frame_terms(self.get_frame_id(frame))[0].copy()

    def get_frame_jacobian(self, frame: str) -> np.ndarray:
        return self.frame_terms(self.get_frame_id(frame))[1].copy()

    def get_frame_velocity(self, frame: str) -> np.ndarray:
        return self.frame_terms(self.get_frame_id(frame))[2].copy()

    def get_frame_bias_acceleration(self, frame: str) -> np.ndarray:
        """
        Return J_dot * nu of ``frame`` in the base frame.

        It is the acceleration at zero generalized acceleration.
        """
        return self.frame_terms(self.get_frame_id(frame))[3].copy()

    def _world_or_frame(self, frame: str):
        fid = self.get_frame_id(frame)
        if fid < 0:
            nv = self.model.nv
            return np.eye(4), np.zeros((6, nv)), np.zeros(6), np.zeros(6)
        return self.world_frame_terms(fid)

    def get_relative_transform(self, reference_frame: str, frame: str) -> np.ndarray:
        """reference_H_frame."""
        return fk.relative_pose(
            self._world_or_frame(reference_frame)[0], self._world_or_frame(frame)[0]
        )

    def get_relative_jacobian(self, reference_frame: str, frame: str) -> np.ndarray:
        Tb, Jb, _, _ = self._world_or_frame(reference_frame)
        Tf, Jf, _, _ = self._world_or_frame(frame)
        return fk.relative_jacobian(Tb, Jb, Tf, Jf)

    def get_relative_velocity(self, reference_frame: str, frame: str) -> np.ndarray:
        Tb, _, vb, _ = self._world_or_frame(reference_frame)
        Tf, _, vf, _ = self._world_or_frame(frame)
        return fk.relative_velocity(Tb, vb, Tf, vf)

    def get_relative_bias_acceleration(self, reference_frame: str, frame: str) -> np.ndarray:
        Tb, _, vb, ab = self._world_or_frame(reference_frame)
        Tf, _, vf, af = self._world_or_frame(frame)
        return fk.relative_bias_acceleration(Tb, vb, ab, Tf, vf, af)
