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
Rotation helpers: quaternions from angle conventions, rotation log map, pose errors.

Quaternions are returned as ``pinocchio.Quaternion`` (Eigen-like: ``.toRotationMatrix()``,
``.coeffs()`` in x, y, z, w order).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def _rot_x(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_from_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """
    R = Rz(yaw) Ry(pitch) Rx(roll).

    fixed-axis roll about x, then pitch about y, then yaw about z.
    """
    return _rot_z(yaw) @ _rot_y(pitch) @ _rot_x(roll)


_ORIGIN = np.zeros(3)


def quaternion_xyzw(R: np.ndarray) -> np.ndarray:
    """
    Return the unit quaternion (x, y, z, w) of a rotation matrix.

    Goes through ``pin.SE3ToXYZQUAT``: constructing ``pin.Quaternion`` from a matrix leaks memory
    at every call in Pinocchio 4.1's bindings, which a 1 kHz loop running for hours cannot
    afford.
    """
    return pin.SE3ToXYZQUAT(pin.SE3(np.asarray(R, dtype=float), _ORIGIN))[3:]


def quat_from_matrix(R: np.ndarray) -> pin.Quaternion:
    """
    Return the ``pin.Quaternion`` of a rotation matrix.

    Built from its coefficients, see :func:`quaternion_xyzw`.
    """
    return pin.Quaternion(quaternion_xyzw(R))


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> pin.Quaternion:
    """Quaternion of :func:`rotation_from_rpy`."""
    return quat_from_matrix(rotation_from_rpy(roll, pitch, yaw))


def quat_from_kuka_convention(a: float, b: float, c: float) -> pin.Quaternion:
    """
    Convert KUKA's (A, B, C) angles.

    A about z, then B about the new y, then C about the new x (ZY'X'').
    """
    return quat_from_matrix(_rot_z(a) @ _rot_y(b) @ _rot_x(c))


def rpy_from_rotation(R: np.ndarray) -> np.ndarray:
    """Inverse of :func:`rotation_from_rpy` (roll, pitch, yaw), pitch in [-pi/2, pi/2]."""
    return np.asarray(pin.rpy.matrixToRpy(np.asarray(R, dtype=float)))


def rotation_log(R: np.ndarray) -> np.ndarray:
    """Rotation vector (axis * angle) of R, angle in [0, pi]."""
    return np.asarray(pin.log3(np.asarray(R, dtype=float)))


def orientation_error(R_desired: np.ndarray, R_current: np.ndarray) -> np.ndarray:
    """
    Rotation vector taking the current orientation to the desired one, in the reference frame.

    It is log(R_d R_c^T): the angular-velocity direction (expressed in the frame both rotations are
    given in) that closes the error, so it can be fed to a PD law acting on angular velocities.
    """
    return np.asarray(pin.log3(R_desired @ R_current.T))


def pose_error(T_desired: np.ndarray, T_current: np.ndarray) -> np.ndarray:
    """
    Return the 6-vector [p_d - p_c, log(R_d R_c^T)] between two 4x4 homogeneous transforms.

    Both are in the same reference frame.
    """
    err = np.empty(6)
    err[:3] = T_desired[:3, 3] - T_current[:3, 3]
    err[3:] = pin.log3(T_desired[:3, :3] @ T_current[:3, :3].T)
    return err


def make_transform(position=(0.0, 0.0, 0.0), rotation=None) -> np.ndarray:
    """4x4 homogeneous transform from a position and a 3x3 rotation matrix or a quaternion."""
    T = np.eye(4)
    T[:3, 3] = np.asarray(position, dtype=float).reshape(3)
    if rotation is not None:
        if isinstance(rotation, pin.Quaternion):
            rotation = rotation.toRotationMatrix()
        T[:3, :3] = np.asarray(rotation, dtype=float).reshape(3, 3)
    return T


def is_rotation_matrix(R: np.ndarray, tol: float = 1e-6) -> bool:
    R = np.asarray(R, dtype=float)
    return (
        R.shape == (3, 3)
        and np.allclose(R @ R.T, np.eye(3), atol=tol)
        and abs(np.linalg.det(R) - 1) < tol
    )


_I3 = np.eye(3)


def is_rotation(R, tol: float = 1e-6) -> bool:
    """
    Tell whether R is a proper rotation matrix (orthonormal to ``tol``, determinant +1).

    Cheap enough for every cycle.
    """
    E = R @ R.T
    E -= _I3
    if not float(np.abs(E).max()) <= tol:  # also False for NaN
        return False
    # orthonormal: the determinant is +-1; +1 iff the third column is the cross product of the
    # first two
    return (
        float(
            R[0, 0] * (R[1, 1] * R[2, 2] - R[2, 1] * R[1, 2])
            - R[0, 1] * (R[1, 0] * R[2, 2] - R[2, 0] * R[1, 2])
            + R[0, 2] * (R[1, 0] * R[2, 1] - R[2, 0] * R[1, 1])
        )
        > 0.0
    )
