"""Servo controllers turning task references into desired accelerations."""
from .cartesian_acceleration_pid import CartesianAccelerationPID
from .pid_controller import PIDController

__all__ = ["CartesianAccelerationPID", "PIDController"]
