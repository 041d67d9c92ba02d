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
Cartesian servo: turns a desired pose/twist/acceleration into a desired frame acceleration.

    a_des = a_ref + P * e_pose + I * integral(e_pose) + D * (v_ref - v)

with e_pose = [p_ref - p, log(R_ref R^T)], everything in the robot's base frame (linear part
first).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .pid_controller import PIDController
from ..common.watched import Watched
from ..math.rotations import is_rotation


class CartesianAccelerationPID(Watched):
    def __init__(self, name: str = 'cartesian_servo'):
        self.name = name
        self._pid = PIDController(6)
        self._robot = None
        self._frame: str | None = None
        self.fid: int | None = None
        self._pose_ref = np.eye(4)
        self._vel_ref = np.zeros(6)
        self._acc_ref = np.zeros(6)
        self._has_desired = False
        self._pose = np.eye(4)
        self._vel = np.zeros(6)
        self._pose_err = np.zeros(6)
        self._vel_err = np.zeros(6)
        self._cmd = np.zeros(6)

    # -------------------------------------------------------------- configuration
    def pid(self) -> PIDController:
        return self._pid

    def set_robot_model(self, robot) -> None:
        self._robot = robot
        if self._frame is not None:
            self.fid = robot.get_frame_id(self._frame)

    def set_control_frame(self, frame: str) -> None:
        if self._robot is not None:
            self.fid = self._robot.get_frame_id(frame)  # raises on unknown frames
        self._frame = frame

    def get_control_frame(self) -> str | None:
        return self._frame

    def set_desired(self, pose, velocity=None, acceleration=None) -> None:
        """Desired 4x4 pose and 6-vectors twist/acceleration ([linear; angular], base frame)."""
        T = np.asarray(pose, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError(f'desired pose must be a finite 4x4 matrix, got shape {T.shape}')
        R = T[:3, :3]
        if not is_rotation(R):
            raise ValueError('desired pose: rotation block is not a rotation matrix')
        v = np.zeros(6) if velocity is None else np.asarray(velocity, dtype=float).reshape(-1)
        a = (
            np.zeros(6)
            if acceleration is None
            else np.asarray(acceleration, dtype=float).reshape(-1)
        )
        for what, x in (('velocity', v), ('acceleration', a)):
            if x.shape != (6,) or not np.all(np.isfinite(x)):
                raise ValueError(f'desired {what} must be a finite 6-vector')
        self._pose_ref[:] = T
        self._vel_ref[:] = v
        self._acc_ref[:] = a
        self._has_desired = True

    def get_desired(self):
        return self._pose_ref.copy(), self._vel_ref.copy(), self._acc_ref.copy()

    def has_desired(self) -> bool:
        return self._has_desired

    def hold_current_pose(self) -> None:
        """Desired := current pose, zero twist and acceleration."""
        self._read_state()
        self.set_desired(self._pose, None, None)

    # -------------------------------------------------------------- run time
    def _read_state(self):
        if self._robot is None or self.fid is None:
            raise RuntimeError(
                f"servo '{self.name}': robot model and control frame must be set first"
            )
        terms = self._robot.frame_terms(self.fid)
        self._pose[:] = terms[0]
        self._vel[:] = terms[2]
        return terms

    def update(self, current_time: float, dt: float) -> np.ndarray:
        """Compute and return the desired frame acceleration (array reused between calls)."""
        self._read_state()
        pe = self._pose_err
        pe[:3] = self._pose_ref[:3, 3] - self._pose[:3, 3]
        pe[3:] = pin.log3(self._pose_ref[:3, :3] @ self._pose[:3, :3].T)
        np.subtract(self._vel_ref, self._vel, out=self._vel_err)
        cmd = self._pid.compute_command(pe, self._vel_err, dt)
        np.add(self._acc_ref, cmd, out=self._cmd)
        return self._cmd

    def get_command(self) -> np.ndarray:
        return self._cmd.copy()

    def get_current_cartesian_pose(self) -> np.ndarray:
        self._read_state()
        return self._pose.copy()

    def get_current_cartesian_velocity(self) -> np.ndarray:
        self._read_state()
        return self._vel.copy()

    def get_cartesian_pose_error(self) -> np.ndarray:
        return self._pose_err.copy()

    def get_cartesian_velocity_error(self) -> np.ndarray:
        return self._vel_err.copy()
