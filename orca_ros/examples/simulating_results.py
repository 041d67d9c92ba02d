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
Simulating the controller.

The arm's dynamics are integrated with the controller's torques, from q = 0 towards the reference
example's Cartesian target.

The reference target (1.0, 0.75, 0.5) m lies 1.26 m from this arm's shoulder while the arm is only
0.87 m long from shoulder to flange, so it cannot be reached. The example aims at the point of the
same direction from the shoulder at 80 % of the arm's length (``reachable_target``), with the
reference's orientation (identity); a correct fixed-base controller must then *reach* it.

Another arm's URDF works too: its tool frame (the tip of the chain), its shoulder (the link the
second joint moves) and its start posture (q = 0 clipped into the joint limits) come from its
model (see ``arm``), the target from the same rule.
"""

from __future__ import annotations

import sys

import numpy as np

from .arm import posture, shoulder_frame as find_shoulder, tool_frame
from .common import (
    add_standard_constraints,
    integrate,
    make_cartesian_servo,
    make_controller,
    make_robot,
    parse_args,
)
from .. import CartesianTask, get_logger, make_transform

_LOG = get_logger('examples.simulating_results')
REFERENCE_TARGET = np.array([1.0, 0.75, 0.5])


def reachable_target(
    robot,
    target=REFERENCE_TARGET,
    fraction: float = 0.8,
    shoulder_frame: str | None = None,
    tip_frame: str | None = None,
) -> np.ndarray:
    """
    Point in the direction of ``target`` from the shoulder.

    At most ``fraction`` of the arm's length: the distance from the shoulder to the tip at q = 0
    (clipped into the joint limits), the stretched arm for the lwr, the iiwa and the UR5. Frames:
    by default the link the second joint moves and the tip of the chain (lwr: link_2, link_7).
    """
    shoulder_frame = shoulder_frame or find_shoulder(robot)
    tip_frame = tip_frame or tool_frame(robot)
    saved = robot.get_joint_positions(), robot.get_joint_velocities()
    n = robot.get_nr_of_degrees_of_freedom()
    robot.set_robot_state(
        posture(robot, np.zeros(n)), np.zeros(n)
    )  # straight arm: its length is the stretch distance
    shoulder = robot.get_frame_pose(shoulder_frame)[:3, 3]
    length = np.linalg.norm(robot.get_frame_pose(tip_frame)[:3, 3] - shoulder)
    robot.set_robot_state(*saved)
    d = np.asarray(target, dtype=float) - shoulder
    dist = np.linalg.norm(d)
    return shoulder + d / dist * min(dist, fraction * length)


def run(
    urdf: str,
    solver: str = 'daqp',
    duration: float = 10.0,
    dt: float = 0.001,
    remove_gravity: bool = False,
    time_budget: float | None = None,
    base: str | None = None,
    tool: str | None = None,
):
    robot, state = make_robot(urdf, base)
    tool = tool or tool_frame(robot)
    controller = make_controller(robot, solver)
    controller.set_solver_budget(time_budget)
    target = make_transform(reachable_target(robot, tip_frame=tool), np.eye(3))
    servo = make_cartesian_servo(tool, target)
    controller.add_task(CartesianTask, 'CartTask_EE').set_servo_controller(servo)
    trq, pos, vel = add_standard_constraints(controller)
    controller.remove_gravity_torques_from_solution(remove_gravity)
    controller.activate_tasks_and_constraints()
    controller.update(0.0, dt)
    controller.print()
    q, v = state.joint_pos.copy(), state.joint_vel.copy()
    qlo, qhi = pos.get_limits()
    vmax = vel.get_limits()[1]
    tmax = trq.get_limits()[1]
    log = {'t': [], 'q': [], 'v': [], 'tau': [], 'pos_err': [], 'g': []}
    t = 0.0
    ok = True
    steps = int(round(duration / dt))
    for k in range(steps):
        robot.set_robot_state(q, v)
        if not controller.update(t, dt):
            _LOG.warning(
                'no solution at t=%.3f (%s): stopping', t, controller.get_return_code().value
            )
            ok = False
            break
        tau_cmd = controller.get_joint_torque_command()
        g = robot.get_joint_gravity_torques()
        tau_applied = controller.get_solution()[robot.get_configuration_space_dimension():][
            : len(q)
        ]
        p = servo.get_current_cartesian_pose()[:3, 3]
        log['t'].append(t)
        log['q'].append(q.copy())
        log['v'].append(v.copy())
        log['tau'].append(tau_cmd.copy())
        log['g'].append(g.copy())
        log['pos_err'].append(np.linalg.norm(p - target[:3, 3]))
        if k % 1000 == 0:
            _LOG.info(
                't=%.1f s  %s at %s  error %.2e m', t, tool, np.round(p, 4), log['pos_err'][-1]
            )
        # the robot (here: the integrated model) receives the full torques; with gravity removed
        # from the command, its drives would add g(q) back
        q, v = integrate(robot, q, v, tau_applied, dt)
        t += dt
    robot.set_robot_state(q, v)
    final = servo.get_current_cartesian_pose()
    res = {k: np.array(val) for k, val in log.items()}
    res.update(
        ok=ok,
        target=target,
        final_pose=final,
        final_position_error=float(np.linalg.norm(final[:3, 3] - target[:3, 3])),
        final_orientation_error=float(
            np.linalg.norm(__import__('pinocchio').log3(target[:3, :3] @ final[:3, :3].T))
        ),
        q_limits=(qlo, qhi),
        v_max=vmax,
        tau_max=tmax,
        tool=tool,
    )
    return res


def main(argv=None) -> int:
    args = parse_args(
        __doc__, argv, lambda p: p.add_argument('--duration', type=float, default=10.0)
    )
    res = run(
        args.urdf,
        args.solver,
        duration=args.duration,
        time_budget=args.time_budget,
        base=args.base_frame,
        tool=args.tool_frame,
    )
    print(
        f"target {np.round(res['target'][:3, 3], 4)}; final {res['tool']} position "
        f"{np.round(res['final_pose'][:3, 3], 5)}"
    )
    print(
        f"final position error {res['final_position_error'] * 1e3:.4f} mm, "
        f"orientation error {res['final_orientation_error']:.2e} rad"
    )
    return 0 if res['ok'] and res['final_position_error'] < 1e-3 else 1


if __name__ == '__main__':
    sys.exit(main())
