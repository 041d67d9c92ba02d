"""Safe fallback commands (no ROS)."""
from .command_watchdog import CommandWatchdog
from .safe_command import SafeCommand

__all__ = ["CommandWatchdog", "SafeCommand"]
