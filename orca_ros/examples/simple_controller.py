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
Minimal controller.

One Cartesian task on the arm's tool (the lwr's link_7) and the usual joint limits, solved for 2 s
of control cycles at a constant state (no robot is moved), then a ramped shutdown. Another arm's
URDF works too: its tool frame, base frame and the target are derived from it (see ``arm``).
"""

from __future__ import annotations

import sys

import numpy as np

from .arm import to_reach, tool_frame
from .common import (
    add_standard_constraints,
    make_cartesian_servo,
    make_controller,
    make_robot,
    parse_args,
)
from .. import CartesianTask, get_logger, make_transform, quat_from_kuka_convention, quat_from_rpy

_LOG = get_logger('examples.simple_controller')


def run(
    urdf: str,
    solver: str = 'daqp',
    duration: float = 2.0,
    dt: float = 0.001,
    base: str | None = None,
    tool: str | None = None,
):
    robot, state = make_robot(urdf, base)
    tool = tool or tool_frame(robot)
    controller = make_controller(robot, solver)
    # the desired orientation can be written in several equivalent ways
    R = quat_from_rpy(0, 0, 0).toRotationMatrix()
    assert np.allclose(R, quat_from_kuka_convention(0, 0, 0).toRotationMatrix())
    target = make_transform(to_reach(robot, tool, [1.0, 0.75, 0.5]), R)
    cart_task = controller.add_task(CartesianTask, 'CartTask_EE')
    cart_task.set_servo_controller(make_cartesian_servo(tool, target))
    add_standard_constraints(controller)
    controller.activate_tasks_and_constraints()
    solved, cycles = 0, int(round(duration / dt))
    for k in range(cycles):
        t = k * dt
        robot.set_robot_state(
            state.joint_pos, state.joint_vel
        )  # a real robot's measurements go here
        if controller.update(t, dt):
            solved += 1
        else:
            _LOG.warning(
                'no solution at t=%.3f (%s): a real robot would brake here',
                t,
                controller.get_return_code().value,
            )
    result = {
        'cycles': cycles,
        'solver': controller.solver.value,
        'solved': solved,
        'full_solution': controller.get_solution(),
        'torque': controller.get_joint_torque_command(),
        'torque_limit': controller.get_constraint('JointTorqueLimit').get_limits()[1],
        'tool': tool,
        'target': target,
        'acceleration': controller.get_joint_acceleration_command(),
    }
    controller.deactivate_tasks_and_constraints()
    while not controller.tasks_and_constraints_deactivated():
        t += dt
        controller.update(t, dt)
    result['deactivated'] = controller.tasks_and_constraints_deactivated()
    return result


def main(argv=None) -> int:
    args = parse_args(__doc__, argv)
    res = run(args.urdf, args.solver, base=args.base_frame, tool=args.tool_frame)
    with np.printoptions(precision=4, suppress=True):
        print(f"solved {res['solved']}/{res['cycles']} cycles")
        print('Full solution              :', res['full_solution'])
        print('Joint acceleration command :', res['acceleration'])
        print('Joint torque command       :', res['torque'])
    return 0 if res['solved'] == res['cycles'] and res['deactivated'] else 1


if __name__ == '__main__':
    sys.exit(main())
