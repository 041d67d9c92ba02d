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
The callback system with bound methods.

A TaskMonitor object is told when the Cartesian task starts and finishes activating, computes, and
starts and finishes deactivating.

The activation is ramped over 0.5 s.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from .arm import to_reach, tool_frame
from .common import (
    add_standard_constraints,
    make_cartesian_servo,
    make_controller,
    make_robot,
    parse_args,
)
from .. import CartesianTask, make_transform, quat_from_rpy


class TaskMonitor:
    def __init__(self):
        self.events: list[str] = []
        self.compute_calls = 0
        self._activated = False
        self._deactivated = False

    def is_activated(self) -> bool:
        return self._activated

    def is_deactivated(self) -> bool:
        return self._deactivated

    def on_activation(self) -> None:
        self.events.append('activation')
        print('[TaskMonitor] activation started')

    def on_activated(self) -> None:
        self.events.append('activated')
        self._activated = True
        print('[TaskMonitor] activated')

    def on_compute_begin(self, current_time: float, dt: float) -> None:
        self.compute_calls += 1
        print(f'[TaskMonitor] compute begin  t={current_time:.2f} dt={dt:.2f}')

    def on_compute_end(self, current_time: float, dt: float) -> None:
        print(f'[TaskMonitor] compute end    t={current_time:.2f} dt={dt:.2f}')

    def on_deactivation(self) -> None:
        self.events.append('deactivation')
        print('[TaskMonitor] deactivation started')

    def on_deactivated(self) -> None:
        self.events.append('deactivated')
        self._deactivated = True
        print('[TaskMonitor] deactivated')


def run(
    urdf: str,
    solver: str = 'daqp',
    dt: float = 0.1,
    ramp: float = 0.5,
    delay_s: float = 0.0,
    base: str | None = None,
    tool: str | None = None,
):
    robot, _ = make_robot(urdf, base)
    tool = tool or tool_frame(robot)
    controller = make_controller(robot, solver)
    target = make_transform(to_reach(robot, tool, [0.3, -0.5, 0.41]), quat_from_rpy(np.pi, 0, 0))
    cart_task = controller.add_task(CartesianTask, 'CartTask_EE')
    cart_task.set_servo_controller(make_cartesian_servo(tool, target))
    cart_task.set_ramp_duration(ramp)
    add_standard_constraints(controller)
    monitor = TaskMonitor()
    cart_task.on_activation_callback(monitor.on_activation)
    cart_task.on_activated_callback(monitor.on_activated)
    cart_task.on_compute_begin_callback(monitor.on_compute_begin)
    cart_task.on_compute_end_callback(monitor.on_compute_end)
    cart_task.on_deactivation_callback(monitor.on_deactivation)
    cart_task.on_deactivated_callback(monitor.on_deactivated)

    t = 0.0
    weights = []
    controller.activate_tasks_and_constraints()
    while not monitor.is_activated():
        controller.update(t, dt)
        weights.append((t, cart_task.get_effective_weight()))
        t += dt
        time.sleep(delay_s)
    controller.deactivate_tasks_and_constraints()
    while not monitor.is_deactivated():
        controller.update(t, dt)
        weights.append((t, cart_task.get_effective_weight()))
        t += dt
        time.sleep(delay_s)
    return {
        'events': monitor.events,
        'compute_calls': monitor.compute_calls,
        'weights': weights,
        'deactivated': controller.tasks_and_constraints_deactivated(),
    }


def main(argv=None) -> int:
    args = parse_args(
        __doc__, argv, lambda p: p.add_argument('--delay-ms', type=float, default=0.0)
    )
    res = run(
        args.urdf,
        args.solver,
        delay_s=args.delay_ms / 1000.0,
        base=args.base_frame,
        tool=args.tool_frame,
    )
    print('events:', ' -> '.join(res['events']))
    expected = ['activation', 'activated', 'deactivation', 'deactivated']
    return 0 if res['events'] == expected and res['deactivated'] else 1


if __name__ == '__main__':
    sys.exit(main())
