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
Callbacks as lambdas/closures driving a minimum-jerk Cartesian trajectory.

When the task is activated, the trajectory starts from link_7's current position towards (0.3,
-0.5, 0.41) m (pointing down), then goes back and forth between that point and (0.5, 0.2, 0.5) m.
On another arm the tool frame and the points come from its model (see ``arm``).

(The reference went back to the start, straight above the base: with the flange pointing down that
pose is out of reach.) The arm's dynamics are integrated so the tracking can be checked.
"""

from __future__ import annotations

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
from .. import CartesianTask, make_transform, MinJerkPositionTrajectory, quat_from_rpy


def run(
    urdf: str,
    solver: str = 'daqp',
    duration: float = 5.0,
    loops: int = 4,
    dt: float = 0.001,
    base: str | None = None,
    tool: str | None = None,
):
    robot, state = make_robot(urdf, base)
    tool = tool or tool_frame(robot)
    controller = make_controller(robot, solver)
    servo = make_cartesian_servo(tool)
    cart_task = controller.add_task(CartesianTask, 'CartTask_EE')
    cart_task.set_servo_controller(servo)
    add_standard_constraints(controller)

    pose_ref = make_transform(
        to_reach(robot, tool, [0.3, -0.5, 0.41]), quat_from_rpy(np.pi, 0, 0)
    )
    end_position = pose_ref[:3, 3].copy()
    other_position = to_reach(robot, tool, [0.5, 0.2, 0.5])
    vel_ref, acc_ref = np.zeros(6), np.zeros(6)
    traj = MinJerkPositionTrajectory(duration)
    ctx = {'loops': 0, 'start': None, 'errors': []}

    cart_task.on_activation_callback(lambda: print('Activating CartesianTask...'))

    def on_activated():
        ctx['start'] = servo.get_current_cartesian_pose()[:3, 3].copy()
        traj.reset_trajectory(ctx['start'], end_position)
        print('CartesianTask activated: trajectory starts')

    cart_task.on_activated_callback(on_activated)

    def on_begin(t, dt_):
        if (
            ctx['start'] is None
        ):  # the first cycle runs before the 'activated' callback: hold still
            servo.hold_current_pose()
            return
        p, v, a = traj.get_desired(t)
        pose_ref[:3, 3] = p
        vel_ref[:3], acc_ref[:3] = v, a
        servo.set_desired(pose_ref, vel_ref, acc_ref)
        ctx['errors'].append(np.linalg.norm(servo.get_current_cartesian_pose()[:3, 3] - p))

    cart_task.on_compute_begin_callback(on_begin)

    def on_end(t, dt_):
        if traj.is_trajectory_finished() and ctx['loops'] < loops:
            ctx['loops'] += 1
            forward = ctx['loops'] % 2 == 1
            traj.reset_trajectory(
                end_position if forward else other_position,
                other_position if forward else end_position,
            )
            print(f"Changing trajectory direction ({ctx['loops']}/{loops}).")

    cart_task.on_compute_end_callback(on_end)
    cart_task.on_deactivation_callback(lambda: print('Deactivating task.'))
    cart_task.on_deactivated_callback(lambda: print('CartesianTask deactivated.'))

    controller.activate_tasks_and_constraints()
    q, v = state.joint_pos.copy(), state.joint_vel.copy()
    t = 0.0
    ok = True
    while ctx['loops'] < loops:
        robot.set_robot_state(q, v)
        if not controller.update(t, dt):
            ok = False
            break
        tau = controller.get_joint_torque_command()
        q, v = integrate(robot, q, v, tau, dt)
        t += dt
    controller.deactivate_tasks_and_constraints()
    while not controller.tasks_and_constraints_deactivated():
        robot.set_robot_state(q, v)
        controller.update(t, dt)
        q, v = integrate(robot, q, v, controller.get_joint_torque_command(), dt)
        t += dt
    errors = np.array(ctx['errors'])
    # the first segment starts with a 180 deg orientation error; the loops after it must be tracked
    # closely
    looping = errors[len(errors) // (loops + 1):]
    return {
        'ok': ok,
        'loops': ctx['loops'],
        'max_tracking_error': float(looping.max()),
        'rms_tracking_error': float(np.sqrt(np.mean(looping**2))),
        'time': t,
        'first_segment_max_error': float(errors[: len(errors) // (loops + 1)].max()),
        'tool': tool,
        'points': (end_position, other_position),
    }


def main(argv=None) -> int:
    args = parse_args(
        __doc__, argv, lambda p: p.add_argument('--duration', type=float, default=5.0)
    )
    res = run(
        args.urdf,
        args.solver,
        duration=args.duration,
        base=args.base_frame,
        tool=args.tool_frame,
    )
    print(
        f"{res['loops']} trajectory segments in {res['time']:.2f} s; tracking error "
        f"max {res['max_tracking_error'] * 1e3:.4f} mm, rms {res['rms_tracking_error'] * 1e3:.4f} "
        'mm'
    )
    return 0 if res['ok'] and res['max_tracking_error'] < 1e-3 else 1


if __name__ == '__main__':
    sys.exit(main())
