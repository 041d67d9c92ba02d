"""Maths helpers (rotations, poses, ramps)."""
from .rotations import (
    is_rotation_matrix,
    make_transform,
    orientation_error,
    pose_error,
    quat_from_kuka_convention,
    quat_from_rpy,
    rotation_from_rpy,
    rotation_log,
    rpy_from_rotation,
)
from .smooth_ramp import smooth_ramp, smooth_ramp_derivative

__all__ = [
    "is_rotation_matrix", "make_transform", "orientation_error", "pose_error", "quat_from_kuka_convention",
    "quat_from_rpy", "rotation_from_rpy", "rotation_log", "rpy_from_rotation", "smooth_ramp",
    "smooth_ramp_derivative",
]
