"""Safe fallback commands (no ROS)."""
from .safe_command import SafeCommand

__all__ = ["SafeCommand"]
