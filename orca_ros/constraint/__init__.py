"""Constraints: linear bounds on the reduced QP variables."""
from .dynamics_equation_constraint import DynamicsEquationConstraint
from .generic_constraint import GenericConstraint, JointBoxConstraint
from .joint_limit_constraints import (
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)

__all__ = [
    "DynamicsEquationConstraint", "GenericConstraint", "JointAccelerationLimitConstraint", "JointBoxConstraint",
    "JointPositionLimitConstraint", "JointTorqueLimitConstraint", "JointVelocityLimitConstraint",
]
