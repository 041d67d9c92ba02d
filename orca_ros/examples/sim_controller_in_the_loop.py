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
Using the simulator to run a controller.

PyBullet is the robot, the core controller runs in its after-step callback (1 kHz), with a
Cartesian task following a minimum-jerk trajectory between two points (also the reference's
trajectory-following example), and the usual limits. Any arm's URDF: its tool frame, start
posture and the two points come from its model (see ``arm``).
"""

from __future__ import annotations

import sys

import numpy as np

from .arm import add_frame_args, posture, to_reach, tool_frame
from .common import add_standard_constraints, make_cartesian_servo, make_controller, make_robot
from .sim_common import parse_sim_args
from .. import CartesianTask, make_transform, MinJerkPositionTrajectory, quat_from_rpy
from ..sim import SimServer


def run(
    urdf: str,
    duration: float = 6.0,
    gui: bool = False,
    segment: float = 2.0,
    base: str | None = None,
    tool: str | None = None,
):
    robot, _ = make_robot(urdf, base)
    tool = tool or tool_frame(robot)
    controller = make_controller(robot)
    servo = make_cartesian_servo(tool)
    controller.add_task(CartesianTask, 'CartTask_EE').set_servo_controller(servo)
    add_standard_constraints(controller)
    a = to_reach(robot, tool, [0.45, -0.25, 0.45])
    b = to_reach(robot, tool, [0.45, 0.25, 0.55])
    R = quat_from_rpy(np.pi, 0, 0).toRotationMatrix()
    traj = MinJerkPositionTrajectory(segment)
    ctx = {'errors': [], 'leg': 0, 'settled': False}
    with SimServer(gui=gui) as server:
        model = server.insert_model_from_urdf_file(urdf)
        q0 = posture(robot, [0.0, 0.6, 0.0, -1.4, 0.0, 0.9, 0.0])
        by_name = model.joint_map(robot.get_joint_names())  # the simulator's order may differ
        model.set_model_configuration(by_name.names, q0)
        robot.set_robot_state(q0, np.zeros(q0.size))
        servo.set_desired(make_transform(a, R))  # first go to the start point and settle
        controller.activate_tasks_and_constraints()

        def step(n, t, dt):
            robot.set_robot_state(
                model.get_joint_positions(by_name), model.get_joint_velocities(by_name)
            )
            if t > 1.5 and not ctx['settled']:
                ctx['settled'] = True
                traj.reset_trajectory(a, b)
            if ctx['settled']:
                p, v, acc = traj.get_desired(t)
                servo.set_desired(make_transform(p, R), np.r_[v, 0, 0, 0], np.r_[acc, 0, 0, 0])
                ctx['errors'].append(np.linalg.norm(robot.get_frame_pose(tool)[:3, 3] - p))
                if traj.is_trajectory_finished():
                    ctx['leg'] += 1
                    traj.reset_trajectory(*((b, a) if ctx['leg'] % 2 else (a, b)))
            if controller.update(t, dt):
                model.set_joint_torque_command(controller.get_joint_torque_command(), by_name)
            else:
                model.set_brakes(True)

        model.execute_after_world_update(step)
        server.run(duration)
    e = np.array(ctx['errors'])
    return {
        'max_error': float(e.max()),
        'rms_error': float(np.sqrt(np.mean(e**2))),
        'legs': ctx['leg'],
        'tool': tool,
        'points': (a, b),
    }


def main(argv=None) -> int:
    args = parse_sim_args(__doc__, argv, add_frame_args)
    res = run(
        args.urdf,
        max(args.duration, 4.0),
        args.gui,
        base=args.base_frame,
        tool=args.tool_frame,
    )
    print(
        f"{res['legs']} trajectory legs; tracking error in PyBullet: max "
        f"{res['max_error'] * 1e3:.2f} mm, "
        f"rms {res['rms_error'] * 1e3:.2f} mm"
    )
    return 0 if res['max_error'] < 5e-3 and res['legs'] >= 1 else 1


if __name__ == '__main__':
    sys.exit(main())
