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
Run-time parameter changes of the controller node (mixed into the node).

Checked against :mod:`.parameter_schema` and applied at once: gains, weights, ramps, activation,
trajectory limits, timeouts, the joint impedance's gains.

A request is all or nothing: every parameter is checked (names, types, ranges, sizes) before any is
applied; a refusal carries the reason, which ``ros2 param set`` prints, and one log line.
"""

from __future__ import annotations

import numpy as np
from rcl_interfaces.msg import SetParametersResult

from .joint_state_input import JointStateInput
from .parameter_schema import ParamRejected, validate
from ..servo.target_trajectory import checked_limits
from ..task import CartesianTask


class LiveParameters:
    def setup_live_parameters(self) -> None:
        self.add_on_set_parameters_callback(self._on_set_parameters)

    def _on_set_parameters(self, params):
        tasks = tuple(self.setup.tasks)
        constraints = tuple(c.name for c in self.controller.get_constraints())
        try:
            actions = [
                self._plan_change(p.name, *validate(p.name, p.value, tasks, constraints))
                for p in params
            ]
        except (ParamRejected, ValueError) as exc:
            self.say('warning', 'param:rejected', f'parameter change rejected: {exc}')
            return SetParametersResult(successful=False, reason=str(exc))
        for act in actions:
            act()
        self.get_logger().info(
            'parameters applied: ' + ', '.join(f'{p.name}={p.value!r}' for p in params)
        )
        return SetParametersResult(successful=True)

    def _plan_change(self, name, spec, groups, value):
        """
        Plan one checked change: a closure that applies it.

        Sizes are checked here, before anything is applied.
        """
        key = name.rsplit('.', 1)[-1]
        if 'task' in groups:
            task = self.setup.tasks[groups['task']]
            if '.trajectory.' in name:
                gen = self.targets.trajectories.get(groups['task'])
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
                return lambda: self._set_task_active(task, value)
        if 'constraint' in groups:
            c = self.controller.get_constraint(groups['constraint'])
            return lambda: c.activate() if value else c.deactivate()
        if key in ('position_margin', 'velocity_factor'):
            margin = value if key == 'position_margin' else self._input.margin
            factor = value if key == 'velocity_factor' else self._velocity_factor
            new_input = JointStateInput(
                self.robot, self.setup.joints, self.setup.model_index, margin, factor
            )

            def apply():
                new_input.estimator = self._input.estimator  # its velocity estimate goes on
                self._input = new_input
                self._velocity_factor = factor

            return apply
        if key in ('joint_stiffness', 'joint_damping'):
            command = self.output.command
            gains = command.checked_gains(**{key.split('_')[1]: value})
            return lambda: command.set_gains(*gains)
        if key in ('solver_time_budget', 'solver_max_iterations'):
            slot = 0 if key == 'solver_time_budget' else 1

            def apply_budget():
                self.solver_budget[slot] = value
                self.set_solver_budget(*self.solver_budget)

            return apply_budget
        targets = {
            'state_timeout': (self, 'state_timeout'),
            'target_timeout': (self, 'target_timeout'),
            'safe_damping': (self.safe, 'damping'),
            'safe_ramp': (self.safe, 'ramp'),
            'overrun_factor': (self, 'overrun_factor'),
            'error_warn_threshold': (self.error_watch, 'threshold'),
            'error_warn_time': (self.error_watch, 'duration'),
        }
        obj, attr = targets[key]
        return lambda: setattr(obj, attr, value)

    def _set_task_active(self, task, active: bool) -> None:
        if active:
            task.activate()
            return
        if self._have_state and task.is_computing():
            self._apply_state()
            self._hold_task(task)
        task.deactivate()
