# Copyright 2026 orca_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.
"""Constraints: linear bounds on the reduced QP variables."""

from .balance_constraint import BalanceConstraint, convex_hull_2d
from .bilateral_contact import BilateralContact
from .collision_avoidance import CollisionAvoidanceConstraint
from .contact import Contact, ContactBase, ContactExistenceCondition, surface_contact
from .dynamics_equation_constraint import DynamicsEquationConstraint
from .generic_constraint import GenericConstraint, JointBoxConstraint
from .joint_limit_constraints import (
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)
from .surface_wrench_contact import contact_wrench_cone, SurfaceContact

__all__ = [
    'BalanceConstraint',
    'CollisionAvoidanceConstraint',
    'convex_hull_2d',
    'BilateralContact',
    'Contact',
    'ContactBase',
    'ContactExistenceCondition',
    'surface_contact',
    'SurfaceContact',
    'contact_wrench_cone',
    'DynamicsEquationConstraint',
    'GenericConstraint',
    'JointAccelerationLimitConstraint',
    'JointBoxConstraint',
    'JointPositionLimitConstraint',
    'JointTorqueLimitConstraint',
    'JointVelocityLimitConstraint',
]
