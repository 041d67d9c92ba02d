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
The controller node's run-time parameters, declared once.

type, range, live or read-only, meaning (no ROS).

Like ros2_controllers' generated parameter libraries, one table drives the validation of every
``set_parameters`` request and the documentation (``python -m orca_ros.ros.parameter_schema``
prints it as a Markdown table). Names may hold ``<task>`` / ``<constraint>``, matched against the
configured names. A live parameter is validated and applied at once; a read-only one (structure:
robot, joints, solver, task types, rates) is refused with the reason, as is anything unknown, of
the wrong type or out of range.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
import re
import sys


class ParamRejected(ValueError):
    pass


@dataclass(frozen=True)
class ParamSpec:
    name: str
    kind: str  # "float", "floats" (one or several), "bool", "int", "ints", "str", "strs"
    live: bool
    doc: str
    low: float = -math.inf
    high: float = math.inf
    choices: tuple = ()

    def pattern(self) -> re.Pattern:
        rx = re.escape(self.name).replace(re.escape('<task>'), r'(?P<task>[^.]+)')
        return re.compile(
            '^' + rx.replace(re.escape('<constraint>'), r'(?P<constraint>[^.]+)') + '$'
        )


_F, _FS, _B = 'float', 'floats', 'bool'
SCHEMA: tuple[ParamSpec, ...] = (
    # structure: fixed once the node runs
    ParamSpec(
        'urdf_path',
        'str',
        False,
        "URDF or MJCF file (relative names: the package's urdf/ and mjcf/; menagerie:<name>: the "
        "MuJoCo Menagerie's robot, mujoco-menagerie package); neither this nor robot_description: "
        'the URDF comes from the robot_description topic',
    ),
    ParamSpec('robot_description', 'str', False, 'URDF text, takes precedence over urdf_path'),
    ParamSpec(
        'robot_description_timeout',
        'float',
        False,
        'wait for the robot_description topic this long [s], 0 = forever',
        0.0,
        3600.0,
    ),
    ParamSpec('base_frame', 'str', False, 'frame of Cartesian targets and feedback'),
    ParamSpec(
        'joints',
        'strs',
        False,
        'commanded joints, in the order of the command array; the others are locked in the model '
        'at their measured positions and never commanded',
    ),
    ParamSpec(
        'locked_joint_tolerance',
        _F,
        False,
        'a locked joint that moved more is welded again at its new position [rad or m]',
        0.0,
        1.0,
    ),
    ParamSpec('floating_base', _B, False, 'free-flyer root joint (base pose and twist from odom)'),
    ParamSpec('odom_topic', 'str', False, 'odometry topic of a floating base (nav_msgs/Odometry)'),
    ParamSpec(
        'odom_twist',
        'str',
        False,
        "the base twist: 'measured' (odom's), 'estimated' (from odom's poses), 'auto' (estimated "
        'when the twist covariance[0] is -1, unknown)',
        choices=('auto', 'measured', 'estimated'),
    ),
    ParamSpec('solver', 'str', False, 'QP solver', choices=('daqp', 'proxqp', 'osqp')),
    ParamSpec('compiled', _B, False, 'the compiled cycle (numba); false: the reference path'),
    ParamSpec(
        'resolution_strategy',
        'str',
        False,
        'how levels combine',
        choices=('one_level_weighted', 'multi_level_weighted', 'generalized'),
    ),
    ParamSpec('update_rate', _F, False, 'control rate [Hz]', 1.0, 10000.0),
    ParamSpec(
        'trigger',
        'str',
        False,
        'timer, or one cycle per joint state (lockstep)',
        choices=('timer', 'joint_state'),
    ),
    ParamSpec('command_topic', 'str', False, 'command topic'),
    ParamSpec(
        'command_message',
        'str',
        False,
        'the commands as std_msgs/Float64MultiArray, or sensor_msgs/JointState by name '
        '(docs/command_interfaces.md)',
        choices=('float64_multi_array', 'joint_state'),
    ),
    ParamSpec(
        'command_interface',
        'str',
        False,
        'what the drives take: efforts, positions, velocities, both, or joint impedance '
        '(docs/command_interfaces.md)',
        choices=('effort', 'position', 'velocity', 'position_velocity', 'joint_impedance'),
    ),
    ParamSpec('joint_stiffness', _FS, True, 'joint_impedance: K_p per joint (or one) [Nm/rad]',
              0.0, 1e6),
    ParamSpec('joint_damping', _FS, True, 'joint_impedance: K_d per joint (or one) [Nm s/rad]',
              0.0, 1e5),
    ParamSpec('reference_position_leash', _F, False, 'position, velocity, impedance: the '
              'reference is kept this close to the measured positions [rad]', 1e-6, 10.0),
    ParamSpec('reference_velocity_leash', _F, False, '... and velocities [rad/s]', 1e-6, 100.0),
    ParamSpec('gravity_compensated_by_hardware', _B, False, 'drives add gravity themselves'),
    ParamSpec('kinematic', _B, False, "the model's inertias dropped: joint accelerations only, "
              'for position or velocity drives (docs/command_interfaces.md)'),
    ParamSpec('statistics_window', 'int', False, 'cycles kept for loop statistics', 1, 10_000_000),
    ParamSpec('diagnostics_rate', _F, False, 'diagnostics [Hz], 0 = off', 0.0, 1000.0),
    ParamSpec(
        'feedback_rate', _F, False, 'per-task pose/error feedback [Hz], 0 = off', 0.0, 1000.0
    ),
    ParamSpec('markers', _B, False, '~/markers: CoM, support polygon, contact forces'),
    ParamSpec('marker_force_scale', _F, False, 'contact force arrows [m/N]', 0.0, 1.0),
    ParamSpec('manage_gc', _B, False, 'keep the garbage collector out of the cycle'),
    ParamSpec('gc_period', _F, False, 'young-generation collection period [s]', 0.01, 3600.0),
    ParamSpec(
        'thread_priority',
        'int',
        False,
        "SCHED_FIFO priority of the node's process (0: normal scheduling; refused: a warning)",
        0,
        99,
    ),
    ParamSpec(
        'cpu_affinity', 'ints', False, 'CPUs the process is pinned to (empty: all)', 0, 1023
    ),
    ParamSpec('tasks.<task>.type', 'str', False, 'task type'),
    ParamSpec('tasks.<task>.frame', 'str', False, 'controlled frame'),
    ParamSpec('tasks.<task>.level', 'int', False, 'priority level', 0, 100),
    ParamSpec('constraints.<constraint>.type', 'str', False, 'constraint type'),
    # live
    ParamSpec(
        'state_timeout', _F, True, 'joint state older than this -> safe command [s]', 1e-3, 10.0
    ),
    ParamSpec(
        'target_timeout',
        _F,
        True,
        'target not refreshed for this long is held [s], 0 = never',
        0.0,
        3600.0,
    ),
    ParamSpec('safe_damping', _F, True, 'damping of the safe command [1/s]', 0.0, 500.0),
    ParamSpec('safe_ramp', _F, True, 'fade of the last command into the safe one [s]', 0.0, 10.0),
    ParamSpec(
        'position_margin',
        _F,
        True,
        'joint-state positions beyond the limits by more are rejected [rad]',
        0.0,
        10.0,
    ),
    ParamSpec(
        'velocity_factor',
        _F,
        True,
        'joint-state speeds beyond this many times the limit are rejected',
        1.0,
        1000.0,
    ),
    ParamSpec(
        'solver_time_budget',
        _F,
        True,
        "wall-clock time for a cycle's QP solves [s]; 0 = one period "
        '(timer), 1 s (lockstep: the simulation waits, results do not depend on the load)',
        0.0,
        10.0,
    ),
    ParamSpec(
        'solver_max_iterations',
        'int',
        True,
        "iteration cap of each solve, 0 = the solver's default",
        0,
        1_000_000,
    ),
    ParamSpec(
        'overrun_factor',
        _F,
        True,
        'a period above this many nominal periods is an overrun',
        1.0,
        100.0,
    ),
    ParamSpec(
        'error_warn_threshold', _F, True, 'task error reported when above this [m] ...', 0.0, 100.0
    ),
    ParamSpec('error_warn_time', _F, True, '... for longer than this [s]', 0.0, 3600.0),
    ParamSpec('tasks.<task>.kp', _FS, True, 'proportional gain(s)', 0.0, 1e6),
    ParamSpec('tasks.<task>.kd', _FS, True, 'derivative gain(s)', 0.0, 1e5),
    ParamSpec('tasks.<task>.ki', _FS, True, 'integral gain(s)', 0.0, 1e6),
    ParamSpec('tasks.<task>.weight', _F, True, 'weight within its level', 0.0, 1e6),
    ParamSpec('tasks.<task>.ramp', _F, True, 'activation / deactivation ramp [s]', 0.0, 60.0),
    ParamSpec('tasks.<task>.active', _B, True, 'switch on / off (ramped; off latches the target)'),
    ParamSpec(
        'tasks.<task>.trajectory.max_velocity', _FS, True, 'trajectory speed limit(s)', 1e-6, 1e3
    ),
    ParamSpec(
        'tasks.<task>.trajectory.max_acceleration',
        _FS,
        True,
        'trajectory acceleration limit(s)',
        1e-6,
        1e4,
    ),
    ParamSpec(
        'tasks.<task>.trajectory.max_jerk', _FS, True, 'trajectory jerk limit(s)', 1e-6, 1e6
    ),
    ParamSpec('constraints.<constraint>.active', _B, True, 'switch on / off (ramped)'),
)


def find(name: str, tasks=(), constraints=()):
    """(spec, match groups) for a parameter name, or None."""
    for spec in SCHEMA:
        m = spec.pattern().match(name)
        if m is None:
            continue
        g = m.groupdict()
        if 'task' in g and g['task'] not in tasks:
            continue
        if 'constraint' in g and g['constraint'] not in constraints:
            continue
        return spec, g
    return None


def _number(x) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise ParamRejected(f'expected a number, got {x!r}')
    return float(x)


def validate(name: str, value, tasks=(), constraints=()):
    """
    Check a run-time change.

    Returns (spec, groups, normalised value); raises ParamRejected with the reason.
    """
    found = find(name, tasks, constraints)
    if found is None:
        raise ParamRejected(f"'{name}' is not a parameter of this controller")
    spec, groups = found
    if not spec.live:
        raise ParamRejected(
            f"'{name}' is read-only at run time (structure: restart the node to change it)"
        )
    if spec.kind == 'bool':
        if not isinstance(value, bool):
            raise ParamRejected(f"'{name}' must be true or false, got {value!r}")
        return spec, groups, value
    if spec.kind in ('float', 'floats'):
        vals = (
            list(value)
            if isinstance(value, (list, tuple)) or type(value).__name__ == 'array'
            else [value]
        )
        if spec.kind == 'float' and len(vals) != 1 or not vals:
            raise ParamRejected(f"'{name}' must be one number, got {value!r}")
        try:
            nums = [_number(v) for v in vals]
        except ParamRejected as exc:
            raise ParamRejected(f"'{name}': {exc}") from None
        for v in nums:
            if not (math.isfinite(v) and spec.low <= v <= spec.high):
                raise ParamRejected(f"'{name}' = {v!r} outside [{spec.low:g}, {spec.high:g}]")
        return spec, groups, nums[0] if spec.kind == 'float' else nums
    if spec.kind == 'int':
        if isinstance(value, bool) or not isinstance(value, int):
            raise ParamRejected(f"'{name}' must be an integer, got {value!r}")
        if not spec.low <= value <= spec.high:
            raise ParamRejected(f"'{name}' = {value!r} outside [{spec.low:g}, {spec.high:g}]")
        return spec, groups, value
    raise ParamRejected(f"'{name}' cannot be changed at run time")


def markdown() -> str:
    rows = [
        '| parameter | type | range / choices | at run time | meaning |',
        '|---|---|---|---|---|',
    ]
    for s in SCHEMA:
        rng = (
            ', '.join(s.choices)
            if s.choices
            else ('' if s.kind in ('bool', 'str', 'strs') else f'[{s.low:g}, {s.high:g}]')
        )
        rows.append(
            f"| `{s.name}` | {s.kind} | {rng} | {'live' if s.live else 'read-only'} | {s.doc} |"
        )
    return '\n'.join(rows)


if __name__ == '__main__':
    sys.stdout.write(markdown() + '\n')
