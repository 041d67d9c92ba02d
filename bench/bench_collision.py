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
Cost of collision avoidance: Controller.update() on the Panda with and without it.

Scenario (example-robot-data's Panda and its SRDF, default controller settings: compiled cycle,
DAQP, multi-level strategy): a hand pose task following a straight minimum-jerk sweep (2 s) past a
ball of 10 cm radius on its path, a joint posture (weight 1e-3), torque / position / velocity
limits; closed loop on the rigid-body model for 3 s. "with": plus ``CollisionAvoidanceConstraint``
at its defaults (every pair the SRDF leaves enabled, 44, and the ball); "without": the same run
with neither. The hand goes round the ball in the first, through it in the second.

Each round runs the two in fresh processes, one after the other (interleaved: a busy spell of the
machine hits both alike); medians over the rounds of each process's median and p99 per cycle. The
target (issue 21): with <= 2x without.

Usage: python bench/bench_collision.py [--rounds 5]
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, 'peer'))
TARGET = 2.0


def run(with_collision: bool) -> dict:
    import orca_ros as orca
    import pinocchio as pin
    from orca_ros.examples.common import integrate
    from scenarios import example_robot_data

    urdf = example_robot_data('panda_description/urdf/panda.urdf')
    srdf = example_robot_data('panda_description/srdf/panda.srdf')
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    model = robot.model
    q0 = np.array([-0.7, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])
    q1 = q0.copy()
    q1[0] = 0.7
    data, hand = model.createData(), model.getFrameId('panda_hand')

    def hand_pose(q):
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[hand].homogeneous.copy()

    T0, T1 = hand_pose(q0), hand_pose(q1)
    robot.set_robot_state(q0, np.zeros(model.nv))
    c = orca.Controller('bench', robot)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('panda_hand')
    ee.servo_controller().pid().set_proportional_gain([100.0] * 6)
    ee.servo_controller().pid().set_derivative_gain([20.0] * 6)
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(1e-3)
    posture.set_desired(q0)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position')
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity')
    pairs = 0
    if with_collision:
        ball = np.eye(4)
        ball[:3, 3] = 0.5 * (T0[:3, 3] + T1[:3, 3])
        col = c.add_constraint(orca.CollisionAvoidanceConstraint('collision', srdf=srdf))
        col.add_obstacle('ball', 'sphere', [0.1], ball)
    c.activate_tasks_and_constraints()
    if with_collision:
        pairs = len(col.geometry.geom_model.collisionPairs)
    q, v, dt = q0.copy(), np.zeros(model.nv), 1e-3
    times, failures = [], 0
    gc.disable()
    try:
        for k in range(3000):
            s = min(1.0, k * dt / 2.0)
            T = T0.copy()
            T[:3, 3] += (10 * s**3 - 15 * s**4 + 6 * s**5) * (T1[:3, 3] - T0[:3, 3])
            ee.servo_controller().set_desired(T)
            robot.set_robot_state(q, v)
            t0 = time.perf_counter()
            failures += not c.update(k * dt, dt)
            times.append(time.perf_counter() - t0)
            q, v = integrate(robot, q, v, c.get_joint_torque_command(), dt)
    finally:
        gc.enable()
    us = np.asarray(times[100:]) * 1e6  # after the first cycles (caches, lazy set-up)
    return {'median': float(np.median(us)), 'p99': float(np.percentile(us, 99)),
            'failures': failures, 'pairs': pairs, 'compiled': bool(c.compiled)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--one', choices=('with', 'without'), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(run(args.one == 'with')))
        return
    got = {'without': [], 'with': []}
    for _ in range(args.rounds):
        for which in got:
            out = subprocess.run([sys.executable, __file__, '--one', which], check=True,
                                 capture_output=True, text=True).stdout
            got[which].append(json.loads(out.strip().splitlines()[-1]))
    row = {w: {key: float(np.median([r[key] for r in rs])) for key in ('median', 'p99')}
           for w, rs in got.items()}
    first = got['with'][0]
    pairs, compiled = first['pairs'], first['compiled']
    print(f'Panda, {pairs} pairs (SRDF) + a ball, compiled cycle {compiled}, median over '
          f'{args.rounds} interleaved rounds:')
    print('             median us   p99 us   failed cycles')
    for w, rs in got.items():
        median, p99 = row[w]['median'], row[w]['p99']
        failed = sum(r['failures'] for r in rs)
        print(f'{w:>10}   {median:9.1f}   {p99:6.1f}   {failed}')
    ratio = row['with']['median'] / row['without']['median']
    ratio99 = row['with']['p99'] / row['without']['p99']
    verdict = 'met' if ratio <= TARGET else 'NOT met'
    print(f'ratio with / without: median {ratio:.2f}, p99 {ratio99:.2f} (target <= {TARGET:.1f}: '
          f'{verdict})')


if __name__ == '__main__':
    main()
