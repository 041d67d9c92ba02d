"""Tasks: weighted least-squares objectives on the reduced QP variables."""
from .cartesian_task import CartesianTask
from .com_task import CoMTask
from .generic_task import GenericTask
from .joint_acceleration_task import JointAccelerationTask
from .joint_torque_task import JointTorqueTask
from .regularisation_task import RegularisationTask
from .wrench_task import WrenchTask

__all__ = ["CartesianTask", "CoMTask", "GenericTask", "JointAccelerationTask", "JointTorqueTask", "RegularisationTask", "WrenchTask"]
