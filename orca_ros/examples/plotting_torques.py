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
Plotting.

Run the controller for 1 s on the simulated arm and plot the joint torques (PNG; a window only with
--show).
"""

from __future__ import annotations

import os
import sys

import numpy as np

from .arm import to_reach, tool_frame
from .common import (
    add_standard_constraints,
    integrate,
    make_cartesian_servo,
    make_controller,
    make_robot,
    parse_args,
)
from .. import CartesianTask, make_transform, quat_from_rpy


def run(
    urdf: str,
    solver: str = 'daqp',
    total_time: float = 1.0,
    dt: float = 0.001,
    output: str = 'plotting_torques.png',
    show: bool = False,
    base: str | None = None,
    tool: str | None = None,
):
    robot, state = make_robot(urdf, base)
    tool = tool or tool_frame(robot)
    controller = make_controller(robot, solver)
    target = make_transform(to_reach(robot, tool, [0.3, -0.5, 0.41]), quat_from_rpy(np.pi, 0, 0))
    controller.add_task(CartesianTask, 'CartTask_EE').set_servo_controller(
        make_cartesian_servo(tool, target)
    )
    trq, _, _ = add_standard_constraints(controller)
    controller.activate_tasks_and_constraints()
    q, v = state.joint_pos.copy(), state.joint_vel.copy()
    start = robot.get_frame_pose(tool)[:3, 3].copy()
    times, torques = [], []
    t = 0.0
    for _ in range(int(round(total_time / dt))):
        robot.set_robot_state(q, v)
        if controller.update(t, dt):
            tau = controller.get_joint_torque_command()
        else:  # no solution: hold with the equality-only fallback
            tau = controller.compute_kkt_torques()
        times.append(t)
        torques.append(tau.copy())
        q, v = integrate(robot, q, v, tau, dt)
        t += dt
    controller.deactivate_tasks_and_constraints()
    while not controller.tasks_and_constraints_deactivated():
        t += dt
        controller.update(t, dt)
    torques = np.array(torques)

    import matplotlib

    if not show:
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 5))
    for j, name in enumerate(robot.get_joint_names()):
        ax.plot(times, torques[:, j], label=name)
    ax.set_xlabel('time [s]')
    ax.set_ylabel('joint torque [Nm]')
    ax.set_title(f'Joint torques, Cartesian task on {tool}')
    ax.grid(True)
    ax.legend(loc='upper right', ncol=2)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(output)), exist_ok=True)
    fig.savefig(output, dpi=100)
    if show:
        plt.show()
    plt.close(fig)
    return {
        'times': np.array(times),
        'torques': torques,
        'output': output,
        'tau_max': trq.get_limits()[1],
        'tool': tool,
        'target': target,
        'final_position': robot.get_frame_pose(tool)[:3, 3].copy(),
        'start_position': start,
    }


def main(argv=None) -> int:
    def extra(p):
        p.add_argument('--output', default='plotting_torques.png')
        p.add_argument('--show', action='store_true', help='also open a plot window')

    args = parse_args(__doc__, argv, extra)
    res = run(
        args.urdf,
        args.solver,
        output=args.output,
        show=args.show,
        base=args.base_frame,
        tool=args.tool_frame,
    )
    print(f"wrote {res['output']} ({len(res['times'])} samples)")
    return 0 if os.path.isfile(res['output']) and np.all(np.isfinite(res['torques'])) else 1


if __name__ == '__main__':
    sys.exit(main())
