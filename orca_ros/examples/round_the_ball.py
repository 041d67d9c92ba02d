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
Collision avoidance: the Panda sweeps its hand past a ball on its path, with and without it.

example-robot-data's Panda and its SRDF; a hand pose task (kp 100, kd 20) following a straight
minimum-jerk sweep of 2 s, a posture (weight 1e-3), torque, position and velocity limits, the
default controller; a ball of 10 cm radius half-way. 3 s on the rigid-body model, once with
``CollisionAvoidanceConstraint`` at its defaults and once without. The picture: the hand's path
seen from above, the least distance between the robot's collision bodies and the ball (coal, on
the constraint's rounded hulls), and the torques.

Usage: python -m orca_ros.examples.round_the_ball [output.png]
"""

from __future__ import annotations

import glob
import os
import sys

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import integrate
from orca_ros.robot.collision_geometry import CollisionGeometry
import pinocchio as pin

SECONDS, DT = 3.0, 1e-3


def example_robot_data(rel: str) -> str:
    """Return the path of a file of example-robot-data (its wheel, on sys.path)."""
    for p in sys.path:
        hit = glob.glob(os.path.join(p, 'cmeel.prefix', 'share', 'example-robot-data', 'robots',
                                     rel))
        if hit:
            return hit[0]
    raise FileNotFoundError(f'example-robot-data not installed (no {rel})')


class Sweep:
    """
    The scenario, built: the Panda, its controller and the ball (``col``: the constraint, or None).

    Its hand's reference at time t: :meth:`reference`. Shared by the picture, ``bench_collision``
    and ``test_collision_avoidance``.
    """

    Q0 = np.array([-0.7, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])

    def __init__(self, with_constraint: bool):
        self.urdf = example_robot_data('panda_description/urdf/panda.urdf')
        self.srdf = example_robot_data('panda_description/srdf/panda.srdf')
        self.robot = robot = orca.RobotModel()
        robot.load_model_from_file(self.urdf)
        nv = robot.model.nv
        q1 = self.Q0.copy()
        q1[0] = 0.7
        robot.set_robot_state(q1, np.zeros(nv))
        self.T1 = robot.get_frame_pose('panda_hand')
        robot.set_robot_state(self.Q0, np.zeros(nv))
        self.T0 = robot.get_frame_pose('panda_hand')
        self.ball = np.eye(4)
        self.ball[:3, 3] = 0.5 * (self.T0[:3, 3] + self.T1[:3, 3])  # on the straight path
        self.controller = c = orca.Controller('round_the_ball', robot)
        self.ee = ee = c.add_task(orca.CartesianTask, 'ee')
        ee.set_control_frame('panda_hand')
        ee.servo_controller().pid().set_proportional_gain([100.0] * 6)
        ee.servo_controller().pid().set_derivative_gain([20.0] * 6)
        posture = c.add_task(orca.JointAccelerationTask, 'posture')
        posture.set_weight(1e-3)
        posture.set_desired(self.Q0)
        c.add_constraint(orca.JointTorqueLimitConstraint, 'torque')
        c.add_constraint(orca.JointPositionLimitConstraint, 'position')
        c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity')
        self.col = None
        if with_constraint:
            self.col = c.add_constraint(
                orca.CollisionAvoidanceConstraint('collision', srdf=self.srdf))
            self.col.add_obstacle('ball', 'sphere', [0.1], self.ball)
        c.activate_tasks_and_constraints()

    def reference(self, t: float) -> np.ndarray:
        """Return the hand's reference: a minimum-jerk straight line for 2 s, then the target."""
        s = min(1.0, t / 2.0)
        T = self.T0.copy()
        T[:3, 3] += (10 * s**3 - 15 * s**4 + 6 * s**5) * (self.T1[:3, 3] - self.T0[:3, 3])
        return T


def run(with_constraint: bool) -> dict:
    """Run the sweep; return the hand's path, the reference's, the least distance, the torques."""
    sweep = Sweep(with_constraint)
    robot, c, ball = sweep.robot, sweep.controller, sweep.ball
    model = robot.model
    # the measure: the constraint's geometry (its own when it is on)
    geom = sweep.col.geometry if sweep.col else CollisionGeometry(robot, sweep.srdf)
    if sweep.col is None:
        geom.add_obstacle('ball', 'sphere', [0.1], ball)
    with_ball = [k for k in range(len(geom.pairs)) if geom.obstacles['ball'] in geom.pairs[k]]
    data = model.createData()
    q, v = sweep.Q0.copy(), np.zeros(model.nv)
    out = {'hand': [], 'reference': [], 'distance': [], 'tau': [], 'ball': ball[:3, 3],
           'failures': 0}
    for k in range(int(SECONDS / DT)):
        T = sweep.reference(k * DT)
        sweep.ee.servo_controller().set_desired(T)
        robot.set_robot_state(q, v)
        out['failures'] += not c.update(k * DT, DT)
        tau = c.get_joint_torque_command().copy()
        out['tau'].append(tau[:7])
        out['reference'].append(T[:3, 3])
        out['hand'].append(robot.get_frame_pose('panda_hand')[:3, 3])
        pin.forwardKinematics(model, data, robot.buffers.q_pin)
        pin.updateGeometryPlacements(model, data, geom.geom_model, geom.geom_data)
        out['distance'].append(min(pin.computeDistance(geom.geom_model, geom.geom_data, p)
                                   .min_distance for p in with_ball))
        q, v = integrate(robot, q, v, tau, DT)
    return {key: np.asarray(val) for key, val in out.items()}


def draw(runs: dict, path: str, safety: float) -> None:
    """Draw the two runs into ``path`` (PNG)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    t = np.arange(len(runs[True]['tau'])) * DT
    ball = runs[True]['ball']
    ax[0].add_patch(plt.Circle(ball[:2], 0.1, color='0.75', label='ball (10 cm)'))
    ref = runs[True]['reference']
    ax[0].plot(ref[:, 0], ref[:, 1], 'k--', lw=1, label='reference')
    for flag, style in ((False, 'C3'), (True, 'C0')):
        hand = runs[flag]['hand']
        ax[0].plot(hand[:, 0], hand[:, 1], style, label=f"hand, {'with' if flag else 'without'}")
        ax[1].plot(t, runs[flag]['distance'] * 1e3, style,
                   label=f"{'with' if flag else 'without'} the constraint")
    ax[0].set(aspect='equal', xlabel='x [m]', ylabel='y [m]', title='the hand, seen from above')
    ax[0].legend(fontsize=8, loc='lower left')
    ax[1].axhline(safety * 1e3, color='k', lw=0.8, ls=':', label='safety distance')
    ax[1].axhline(0.0, color='0.5', lw=0.8)
    ax[1].set(xlabel='t [s]', ylabel='[mm]', title='least distance, robot to ball')
    ax[1].legend(fontsize=8)
    ax[2].plot(t, runs[True]['tau'], lw=1)
    ax[2].set(xlabel='t [s]', ylabel='[Nm]', title='joint torques, with the constraint')
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    path = argv[0] if argv else 'round_the_ball.png'
    runs = {flag: run(flag) for flag in (False, True)}
    for flag, r in runs.items():
        print(f"{'with' if flag else 'without'} the constraint: least distance "
              f"{r['distance'].min() * 1e3:.1f} mm, {int(r['failures'])} failed cycles, hand "
              f"{np.linalg.norm(r['hand'][-1] - r['reference'][-1]) * 1e3:.2f} mm from target")
    draw(runs, path, orca.CollisionAvoidanceConstraint('c').safety_distance)
    print(f'picture: {path}')


if __name__ == '__main__':
    main()
