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
with neither. The hand goes round the ball in the first, through it in the second. The scenario is
``orca_ros.examples.round_the_ball.Sweep`` (the README's picture).

Each round runs the two in fresh processes, one after the other (interleaved: a busy spell of the
machine hits both alike); medians over the rounds of each process's median and p99 per cycle. The
target (issue 21): with <= 2x without.

Usage: python bench/bench_collision.py [--rounds 5]
"""

from __future__ import annotations

import argparse
import gc
import json
import subprocess
import sys
import time

import numpy as np

TARGET = 2.0


def run(with_collision: bool) -> dict:
    from orca_ros.examples.common import integrate
    from orca_ros.examples.round_the_ball import Sweep

    sweep = Sweep(with_collision)
    robot, c, ee = sweep.robot, sweep.controller, sweep.ee
    pairs = len(sweep.col.geometry.geom_model.collisionPairs) if with_collision else 0
    q, v, dt = sweep.Q0.copy(), np.zeros(robot.model.nv), 1e-3
    times, failures = [], 0
    gc.disable()
    try:
        for k in range(3000):
            ee.servo_controller().set_desired(sweep.reference(k * dt))
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
