"""Tasks: weighted least-squares objectives on the reduced QP variables."""
from .cartesian_task import CartesianTask
from .generic_task import GenericTask
from .joint_acceleration_task import JointAccelerationTask
from .joint_torque_task import JointTorqueTask
from .regularisation_task import RegularisationTask

__all__ = ["CartesianTask", "GenericTask", "JointAccelerationTask", "JointTorqueTask", "RegularisationTask"]
