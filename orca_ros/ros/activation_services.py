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
The controller node's services: activation of tasks and constraints, enable, target reset.

A part of :class:`.controller_node.OrcaControllerNode`. ``~/tasks/<name>/set_active``
(std_srvs/SetBool: the task ramps in or out; out, it is held where the robot is first),
``~/activate`` / ``~/deactivate`` (std_srvs/Trigger: every task and constraint, ramped; before
deactivating, every target latches to the measured state, so nothing pulls while the tasks fade
out), ``~/enable`` (std_srvs/SetBool: false = the node sends its safe command; true again resumes
from the measured state, not from old targets), ``~/reset_targets`` (std_srvs/Trigger: every
target := the measured state). At configuration, the tasks and constraints configured active are
activated here.
"""

from __future__ import annotations

from std_srvs.srv import SetBool, Trigger


class ActivationServices:
    """
    The node's activation services (see the module); ``enabled``: the node controls.

    ``node``: where the services live and whether the robot was seen (``have_state``);
    ``targets``: the :class:`.task_targets.TaskTargets` part (hold, set active).
    """

    def __init__(self, node, setup, controller, targets):
        self.node, self.setup, self.controller, self.targets = node, setup, controller, targets
        self.enabled = True
        for name in setup.tasks:
            node.create_service(SetBool, f'~/tasks/{name}/set_active',
                                lambda rq, rs, n=name: self._on_set_active(n, rq, rs))
        node.create_service(Trigger, '~/activate', self._on_activate)
        node.create_service(Trigger, '~/deactivate', self._on_deactivate)
        node.create_service(SetBool, '~/enable', self._on_enable)
        node.create_service(Trigger, '~/reset_targets', self._on_reset_targets)
        for name, active in setup.initially_active.items():
            if active:
                (setup.tasks.get(name) or controller.get_constraint(name)).activate()

    def _on_set_active(self, name, req, res):
        task = self.setup.tasks[name]
        changed = self.targets.set_active(task, bool(req.data))
        res.success = True
        res.message = (
            f"task '{name}' {'activating' if req.data else 'deactivating'}"
            if changed
            else f"task '{name}' already {task.get_state().value}"
        )
        return res

    def _on_activate(self, req, res):
        self.controller.activate_tasks_and_constraints()
        res.success, res.message = True, 'activating every task and constraint'
        return res

    def _on_deactivate(self, req, res):
        if self.node.have_state:
            self.targets.hold_all()
        self.controller.deactivate_tasks_and_constraints()
        res.success, res.message = (
            True,
            'deactivating every task and constraint (targets latched to the current state)',
        )
        return res

    def _on_enable(self, req, res):
        if req.data and not self.enabled and self.node.have_state:
            self.targets.hold_all()
        self.enabled = bool(req.data)
        res.success = True
        res.message = 'control enabled' if req.data else 'holding (gravity + damping)'
        return res

    def _on_reset_targets(self, req, res):
        if not self.node.have_state:
            res.success, res.message = False, 'no joint state received yet'
            return res
        self.targets.hold_all()
        res.success, res.message = True, 'targets set to the current state'
        return res
