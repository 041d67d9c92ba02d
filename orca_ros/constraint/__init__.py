"""Constraints: linear bounds on the reduced QP variables."""
from .bilateral_contact import BilateralContact
from .contact import Contact, ContactBase, ContactExistenceCondition, surface_contact
from .dynamics_equation_constraint import DynamicsEquationConstraint
from .generic_constraint import GenericConstraint, JointBoxConstraint
from .surface_wrench_contact import SurfaceContact, contact_wrench_cone
from .joint_limit_constraints import (
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)

__all__ = [
    "BilateralContact", "Contact", "ContactBase", "ContactExistenceCondition", "surface_contact",
    "SurfaceContact", "contact_wrench_cone",
    "DynamicsEquationConstraint", "GenericConstraint", "JointAccelerationLimitConstraint", "JointBoxConstraint",
    "JointPositionLimitConstraint", "JointTorqueLimitConstraint", "JointVelocityLimitConstraint",
]
