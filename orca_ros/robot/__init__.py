"""Robot model (Pinocchio) and state container."""
from .robot_model import WORLD_FRAME, RobotModel
from .robot_state import RobotState

__all__ = ["RobotModel", "RobotState", "WORLD_FRAME"]
