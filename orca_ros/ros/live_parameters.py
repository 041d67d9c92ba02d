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
Run-time parameter changes of the controller node (a part of the node).

Checked against :mod:`.parameter_schema` and applied at once: gains, weights, ramps, activation,
trajectory limits, timeouts, the joint impedance's gains.

A request is all or nothing: every parameter is checked (names, types, ranges, sizes) before any is
applied; a refusal carries the reason, which ``ros2 param set`` prints, and one log line.
"""

from __future__ import annotations

import numpy as np
from rcl_interfaces.msg import SetParametersResult

from .parameter_schema import ParamRejected, validate
from ..servo.target_trajectory import checked_limits
from ..task import CartesianTask


class LiveParameters:
    """
    The controller node's run-time parameter changes: a part of the node (see the module).

    ``node`` takes the callback and is what the changes apply to: its configured controller
    (``setup``, ``controller``), its parts (``targets``, ``output``, ``diagnostics``, the
    measured ``state``'s plausibility bounds), its safe command (``safe``), its solver budget
    (``solver_budget``, ``set_solver_budget``) and ``state_timeout``.
    """

    def __init__(self, node):
        self.node = node
        node.add_on_set_parameters_callback(self.on_set_parameters)

    def on_set_parameters(self, params):
        """Check every change of ``params``, then apply them all, or refuse them all."""
        node = self.node
        tasks = tuple(node.setup.tasks)
        constraints = tuple(c.name for c in node.controller.get_constraints())
        try:
            actions = [
                self._plan_change(p.name, *validate(p.name, p.value, tasks, constraints))
                for p in params
            ]
        except (ParamRejected, ValueError) as exc:
            node.say('warning', 'param:rejected', f'parameter change rejected: {exc}')
            return SetParametersResult(successful=False, reason=str(exc))
        for act in actions:
            act()
        node.get_logger().info(
            'parameters applied: ' + ', '.join(f'{p.name}={p.value!r}' for p in params)
        )
        return SetParametersResult(successful=True)

    def _plan_change(self, name, spec, groups, value):
        """
        Plan one checked change: a closure that applies it.

        Sizes are checked here, before anything is applied.
        """
        node = self.node
        key = name.rsplit('.', 1)[-1]
        if 'task' in groups:
            task = node.setup.tasks[groups['task']]
            if '.trajectory.' in name:
                gen = node.targets.smoothing.trajectories.get(groups['task'])
                if gen is None:
                    raise ParamRejected(f"'{name}': trajectories are disabled for this task")
                attr = {'max_velocity': 'vmax', 'max_acceleration': 'amax', 'max_jerk': 'jmax'}[
                    key
                ]
                lim = checked_limits(value, getattr(gen, attr).size, f'{name}')
                return lambda: setattr(gen, attr, lim)
            if key in ('kp', 'kd', 'ki'):
                pid = (
                    task.servo_controller().pid()
                    if isinstance(task, CartesianTask)
                    else task.pid()
                )
                dim = pid.get_proportional_gain().size
                if len(value) not in (1, dim):
                    raise ParamRejected(f"'{name}' needs 1 or {dim} values, got {len(value)}")
                gain = np.full(dim, value[0]) if len(value) == 1 else np.array(value)
                setter = {
                    'kp': pid.set_proportional_gain,
                    'kd': pid.set_derivative_gain,
                    'ki': pid.set_integral_gain,
                }[key]
                return lambda: setter(gain)
            if key == 'weight':
                return lambda: task.set_weight(value)
            if key == 'ramp':
                return lambda: task.set_ramp_duration(value)
            if key == 'active':
                return lambda: node.targets.set_active(task, value)
        if 'constraint' in groups:
            c = node.controller.get_constraint(groups['constraint'])
            return lambda: c.activate() if value else c.deactivate()
        if key in ('position_margin', 'velocity_factor'):
            state = node.state

            def apply_bounds():  # the other bound as it is then (both may change in one request)
                state.set_plausibility(
                    value if key == 'position_margin' else state.joint_input.margin,
                    value if key == 'velocity_factor' else state.velocity_factor,
                )

            return apply_bounds
        if key in ('joint_stiffness', 'joint_damping'):
            command = node.output.command
            gains = command.checked_gains(**{key.split('_')[1]: value})
            return lambda: command.set_gains(*gains)
        if key in ('solver_time_budget', 'solver_max_iterations'):
            slot = 0 if key == 'solver_time_budget' else 1

            def apply_budget():
                node.solver_budget[slot] = value
                node.set_solver_budget(*node.solver_budget)

            return apply_budget
        targets = {
            'state_timeout': (node, 'state_timeout'),
            'target_timeout': (node.targets, 'timeout'),
            'safe_damping': (node.safe, 'damping'),
            'safe_ramp': (node.safe, 'ramp'),
            'overrun_factor': (node.diagnostics, 'overrun_factor'),
            'error_warn_threshold': (node.diagnostics.error_watch, 'threshold'),
            'error_warn_time': (node.diagnostics.error_watch, 'duration'),
        }
        obj, attr = targets[key]
        return lambda: setattr(obj, attr, value)
