"""Utilities: logging, trajectories."""
from .logger import Logger, get_logger
from .min_jerk import MinJerkPositionTrajectory

__all__ = ["Logger", "get_logger", "MinJerkPositionTrajectory"]
