"""PyBullet stand-in for robot hardware (no ROS)."""
from .sim_model import SimModel
from .sim_server import SimServer

__all__ = ["SimModel", "SimServer"]
