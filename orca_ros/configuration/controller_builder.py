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
"""
Build a robot model and a controller from a plain configuration dictionary.

The dictionary is the YAML of ``config/``.

No ROS here: the controller node flattens its parameters into this dictionary, and tests use it
directly.

Keys (defaults in brackets): ``urdf_path`` or ``robot_description``; ``floating_base`` [false];
``base_frame`` [URDF root]; ``joints`` [all, URDF order] (the joints commanded, in the order of
the commands on the wire; the others are welded at their measured positions, see
:class:`orca_ros.robot.joint_locking.LockedJoints`); ``locked_joint_tolerance`` [1e-4];
``solver`` [daqp]; ``resolution_strategy`` [one_level_weighted];
``gravity_compensated_by_hardware`` [false]; ``compiled`` [true] (the compiled cycle; false: the
reference path); ``kinematic`` [false] (the model's inertias dropped: joint accelerations only,
for position or velocity drives; fixed base, no task or constraint that needs the dynamics:
:data:`NEEDS_DYNAMICS`); ``regularisation`` {weight, damping};
``lower_level_damping`` [10] (levels below the first, Controller.set_lower_level_damping);
``tasks``:
{names: [...], <name>: {type, ...}}; ``constraints``: {names: [...], <name>: {type, ...}}.

Task types: ``cartesian`` (frame, kp[6|1], kd, ki, target_position, target_rpy),
``joint_acceleration`` (kp, kd, ki, target), ``joint_torque`` (target); all take weight, ramp,
active [true], selection, level [0] and, with the ``generalized`` strategy, ``priority_over``
{<lower task>: value in [0, 1]} [1: strict]. Task ``com``: kp, kd, target (world). Contacts (in
``constraints``): ``contact`` (frame, offset, friction_coefficient, margin, faces, normal,
max_normal_force, min_normal_force, velocity_gain [0 1/s]), ``bilateral_contact`` (frame,
other_frame). Constraint types: ``joint_torque_limit`` (max or min/max [URDF]),
``joint_position_limit`` (horizon, max_acceleration [5], min/max [URDF]), ``joint_velocity_limit``
(horizon, max [URDF]), ``joint_acceleration_limit`` (max), ``balance`` (margin [0.03 m],
max_acceleration [2 m/s^2], horizon [0.2 s]: the CoM over the contacts' support polygon); all take
ramp and active [true].
"""

from __future__ import annotations

from dataclasses import dataclass, field
import os

import numpy as np

from .collision_config import make_collision_avoidance
from .config_error import ConfigError
from ..constraint import (
    BalanceConstraint,
    BilateralContact,
    Contact,
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)
from ..math.rotations import make_transform, rotation_from_rpy
from ..optim import Controller, QPSolver, ResolutionStrategy
from ..paths import share_path
from ..robot import RobotModel
from ..robot.mjcf import MENAGERIE, menagerie_path
from ..task import CartesianTask, CoMTask, JointAccelerationTask, JointTorqueTask, MomentumTask

TASK_TYPES = {
    'cartesian': CartesianTask,
    'joint_acceleration': JointAccelerationTask,
    'joint_torque': JointTorqueTask,
    'com': CoMTask,
    'momentum': MomentumTask,
}
CONTACT_TYPES = {'contact': Contact, 'bilateral_contact': BilateralContact}
CONSTRAINT_TYPES = {
    'joint_torque_limit': JointTorqueLimitConstraint,
    'joint_position_limit': JointPositionLimitConstraint,
    'joint_velocity_limit': JointVelocityLimitConstraint,
    'joint_acceleration_limit': JointAccelerationLimitConstraint,
    'balance': BalanceConstraint,
}


@dataclass
class ControllerSetup:
    robot: RobotModel
    controller: Controller
    joints: list[str]  # wire order
    model_index: np.ndarray  # model joint k is wire joint model_index[k]
    tasks: dict = field(default_factory=dict)
    task_types: dict = field(default_factory=dict)
    initially_active: dict = field(default_factory=dict)
    gravity_compensated_by_hardware: bool = False
    kinematic: bool = False  # the model's inertias dropped (accelerations only)


def resolve_urdf_path(path: str) -> str:
    """
    Return the robot model file ``path`` (URDF or MJCF): as given, or shipped (urdf/, mjcf/).

    ``menagerie:<name>``: the MuJoCo Menagerie's robot of that name (:func:`.mjcf.menagerie_path`).
    """
    if path.startswith(MENAGERIE):
        try:
            return menagerie_path(path[len(MENAGERIE):])
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    if os.path.isabs(path) or os.path.exists(path):
        return path
    for folder in ('urdf', 'mjcf'):
        try:
            return share_path(folder, path)
        except FileNotFoundError:
            pass
    raise ConfigError(
        f"robot model '{path}' not found (as given, nor in the package's urdf/ or mjcf/ "
        'directory)'
    )


def _vec(value, n, what):
    v = np.asarray(value, dtype=float).reshape(-1)
    if v.size == 1:
        v = np.full(n, float(v[0]))
    if v.size != n or not np.all(np.isfinite(v)):
        raise ConfigError(f'{what}: expected 1 or {n} finite numbers, got {value!r}')
    return v


def build_from_config(cfg: dict) -> ControllerSetup:
    robot = RobotModel()
    floating = bool(cfg.get('floating_base', False))
    if cfg.get('robot_description'):
        robot.load_model_from_string(cfg['robot_description'], floating)
    elif cfg.get('urdf_path'):
        robot.load_model_from_file(resolve_urdf_path(cfg['urdf_path']), floating)
    else:
        raise ConfigError("configuration needs 'robot_description' (URDF text) or 'urdf_path'")
    kinematic = bool(cfg.get('kinematic', False))
    if kinematic:
        _check_kinematic(cfg, floating)
        robot.set_massless()
    if cfg.get('base_frame'):
        robot.set_base_frame(cfg['base_frame'])
    if cfg.get('gravity') is not None:
        robot.set_gravity(cfg['gravity'])
    joints = _lock_other_joints(robot, cfg)
    model_joints = robot.get_joint_names()
    model_index = np.array([joints.index(n) for n in model_joints])
    n = robot.get_nr_of_degrees_of_freedom()

    try:
        solver = QPSolver.from_string(cfg.get('solver', 'daqp'))
        strategy = ResolutionStrategy.from_string(
            cfg.get('resolution_strategy', 'one_level_weighted')
        )
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    # the caller logs controller.solver_fallback where it logs (the node: its ROS logger)
    controller = Controller(
        cfg.get('name', 'orca_controller'),
        robot,
        strategy,
        solver,
        log_solver_fallback=False,
        compiled=bool(cfg.get('compiled', True)),
    )
    reg = cfg.get('regularisation') or {}
    if 'weight' in reg:
        controller.global_regularisation.set_weight(reg['weight'])
    if 'damping' in reg:
        controller.global_regularisation.set_damping(reg['damping'])
    if 'lower_level_damping' in cfg:
        controller.set_lower_level_damping(float(cfg['lower_level_damping']))
    setup = ControllerSetup(
        robot,
        controller,
        joints,
        model_index,
        gravity_compensated_by_hardware=bool(cfg.get('gravity_compensated_by_hardware', False)),
        kinematic=kinematic,
    )
    controller.remove_gravity_torques_from_solution(setup.gravity_compensated_by_hardware)

    tasks = cfg.get('tasks') or {}
    for name in tasks.get('names', []):
        tc = tasks.get(name)
        if not isinstance(tc, dict) or tc.get('type') not in TASK_TYPES:
            raise ConfigError(f"task '{name}': 'type' must be one of {sorted(TASK_TYPES)}")
        task = controller.add_task(TASK_TYPES[tc['type']], name)
        _configure_task(task, tc, n, name)
        setup.tasks[name] = task
        setup.task_types[name] = tc['type']
        setup.initially_active[name] = bool(tc.get('active', True))
    for name in tasks.get('names', []):  # priorities name other tasks: read once all exist
        for low, value in (tasks[name].get('priority_over') or {}).items():
            try:
                controller.set_priority(name, low, float(value))
            except (KeyError, ValueError, TypeError) as exc:
                raise ConfigError(f"task '{name}'.priority_over.{low}: {exc}") from None
    cons = cfg.get('constraints') or {}
    for name in cons.get('names', []):
        cc = cons.get(name)
        if isinstance(cc, dict) and cc.get('type') == 'collision_avoidance':
            c = controller.add_constraint(make_collision_avoidance(name, cc, robot))
            c.set_ramp_duration(float(cc.get('ramp', 0.0)))
            setup.initially_active[name] = bool(cc.get('active', True))
            continue
        if isinstance(cc, dict) and cc.get('type') in CONTACT_TYPES:
            c = controller.add_constraint(_make_contact(name, cc))
            c.set_ramp_duration(float(cc.get('ramp', 0.0)))
            setup.initially_active[name] = bool(cc.get('active', True))
            continue
        if not isinstance(cc, dict) or cc.get('type') not in CONSTRAINT_TYPES:
            raise ConfigError(
                f"constraint '{name}': 'type' must be one of "
                f"{sorted(CONSTRAINT_TYPES) + sorted(CONTACT_TYPES) + ['collision_avoidance']}"
            )
        c = controller.add_constraint(CONSTRAINT_TYPES[cc['type']], name)
        if 'horizon' in cc:
            c.set_horizon(float(cc['horizon']))
        if 'max_acceleration' in cc and cc['type'] == 'joint_position_limit':
            c.set_max_acceleration(_vec(cc['max_acceleration'], n, f'{name}.max_acceleration'))
        if cc['type'] == 'balance':
            _configure_balance(c, cc, name)
        if 'max' in cc or 'min' in cc:
            default = c.get_limits()
            hi = _vec(cc['max'], n, f'{name}.max') if 'max' in cc else default[1]
            lo = (
                _vec(cc['min'], n, f'{name}.min')
                if 'min' in cc
                else (-hi if 'max' in cc and cc['type'] != 'joint_position_limit' else default[0])
            )
            c.set_limits(lo, hi)
        c.set_ramp_duration(float(cc.get('ramp', 0.0)))
        setup.initially_active[name] = bool(cc.get('active', True))
    return setup


#: what the kinematic formulation cannot compute (torques, forces, the mass's motion)
NEEDS_DYNAMICS = ('joint_torque', 'com', 'momentum', 'joint_torque_limit', 'balance', 'contact',
                  'bilateral_contact')


def _check_kinematic(cfg: dict, floating: bool) -> None:
    """Refuse what the kinematic formulation cannot do, naming it (ConfigError)."""
    if floating:
        raise ConfigError('kinematic: a fixed base only (a floating base stands on contact '
                          'forces, which need the dynamics)')
    for group in ('tasks', 'constraints'):
        entries = cfg.get(group) or {}
        for name in entries.get('names', []):
            kind = (entries.get(name) or {}).get('type')
            if kind in NEEDS_DYNAMICS:
                raise ConfigError(f"kinematic: {group[:-1]} '{name}' ({kind}) needs the dynamics "
                                  '(torques, forces or masses): leave it out')


def _configure_balance(c: BalanceConstraint, cc: dict, name: str) -> None:
    try:
        if 'margin' in cc:
            c.set_margin(float(cc['margin']))
        if 'max_acceleration' in cc:
            c.set_max_acceleration(float(cc['max_acceleration']))
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"constraint '{name}': {exc}") from None


def _lock_other_joints(robot: RobotModel, cfg: dict) -> list[str]:
    """Weld the joints ``joints`` leaves out; return ``joints`` (the wire order)."""
    model_joints = robot.get_joint_names()
    joints = list(cfg.get('joints') or model_joints)
    unknown = [j for j in joints if j not in model_joints]
    if unknown or len(set(joints)) != len(joints):
        raise ConfigError(
            f"'joints' must list distinct joints of the robot {model_joints}, got {joints}"
            + (f' (unknown: {unknown})' if unknown else ' (duplicates)')
        )
    others = [j for j in model_joints if j not in joints]
    if others:
        try:
            robot.lock_joints(others, tolerance=float(cfg.get('locked_joint_tolerance', 1e-4)))
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    return joints


_CONTACT_SETTINGS = (  # YAML key, Contact setter, conversion of the value
    ('faces', 'set_number_of_faces', lambda v, _: int(v)),
    ('friction_coefficient', 'set_friction_coefficient', lambda v, _: float(v)),
    ('margin', 'set_margin', lambda v, _: float(v)),
    ('normal', 'set_contact_normal', lambda v, name: _vec(v, 3, f'{name}.normal')),
    ('max_normal_force', 'set_maximum_normal_force', lambda v, _: float(v)),
    ('min_normal_force', 'set_minimum_normal_force', lambda v, _: float(v)),
    ('velocity_gain', 'set_velocity_feedback_gain', lambda v, _: float(v)),
)


def _make_contact(name: str, cc: dict):
    if 'frame' not in cc:
        raise ConfigError(f"contact '{name}' needs a 'frame'")
    try:
        if cc['type'] == 'bilateral_contact':
            return BilateralContact(name, cc['frame'], cc.get('other_frame') or None)
        c = Contact(name, cc['frame'], offset=cc.get('offset'))
        for key, setter, value in _CONTACT_SETTINGS:  # the faces before the coefficient and margin
            if key in cc:
                getattr(c, setter)(value(cc[key], name))
        return c
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"contact '{name}': {exc}") from None


def _configure_task(task, tc: dict, n: int, name: str) -> None:
    task.set_weight(float(tc.get('weight', 1.0)))
    task.set_ramp_duration(float(tc.get('ramp', 0.0)))
    if 'level' in tc:
        task.set_priority_level(int(tc['level']))
    if 'selection' in tc:
        task.set_selection_vector(tc['selection'])
    kind = type(task)
    if kind is CartesianTask:
        if 'frame' not in tc:
            raise ConfigError(f"cartesian task '{name}' needs a 'frame'")
        task.set_control_frame(tc['frame'])
        pid = task.servo_controller().pid()
        pid.set_proportional_gain(_vec(tc.get('kp', 100.0), 6, f'{name}.kp'))
        pid.set_derivative_gain(_vec(tc.get('kd', 20.0), 6, f'{name}.kd'))
        if 'ki' in tc:
            pid.set_integral_gain(_vec(tc['ki'], 6, f'{name}.ki'))
        if 'target_position' in tc:
            rpy = tc.get('target_rpy', [0.0, 0.0, 0.0])
            task.servo_controller().set_desired(
                make_transform(
                    _vec(tc['target_position'], 3, f'{name}.target_position'),
                    rotation_from_rpy(*_vec(rpy, 3, f'{name}.target_rpy')),
                )
            )
    elif kind is JointAccelerationTask:
        task.pid().set_proportional_gain(_vec(tc.get('kp', 10.0), n, f'{name}.kp'))
        task.pid().set_derivative_gain(_vec(tc.get('kd', 2 * np.sqrt(10.0)), n, f'{name}.kd'))
        if 'ki' in tc:
            task.pid().set_integral_gain(_vec(tc['ki'], n, f'{name}.ki'))
        if 'target' in tc:
            task.set_desired(_vec(tc['target'], n, f'{name}.target'))
    elif kind is CoMTask:
        task.pid().set_proportional_gain(_vec(tc.get('kp', 100.0), 3, f'{name}.kp'))
        task.pid().set_derivative_gain(_vec(tc.get('kd', 20.0), 3, f'{name}.kd'))
        if 'target' in tc:
            task.set_desired(_vec(tc['target'], 3, f'{name}.target'))
    elif kind is MomentumTask:
        task.pid().set_proportional_gain(_vec(tc.get('kp', 10.0), 6, f'{name}.kp'))
        if 'ki' in tc:
            task.pid().set_integral_gain(_vec(tc['ki'], 6, f'{name}.ki'))
        if 'target' in tc:
            task.set_desired(_vec(tc['target'], 6, f'{name}.target'))
    elif kind is JointTorqueTask:
        if 'target' in tc:
            task.set_desired(_vec(tc['target'], n, f'{name}.target'))
