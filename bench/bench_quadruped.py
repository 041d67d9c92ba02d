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
Controller.update() on the 12-DoF quadruped standing on four contacts, in PyBullet at 1 kHz.

The standing controller of orca_ros.examples.quadruped (4 point contacts with friction pyramids and
existence conditions, 6-D base task, posture, torque / position / velocity limits: 42 QP variables)
holds the robot for --seconds of simulated time, from a 1 mm drop; only update() is timed, from the
200th cycle, under the default solve budget (one 1 ms period); failed cycles (where the node's
fallback would apply) are counted. Floor, per solver: for the QPs of that solver's run (captured
in a second run, in the solver's units and layout: bench/peer/qp_solvers.py), one Pinocchio
computeAllTerms plus one warm-started solve by that solver with the controller's settings. The
default solver's (DAQP) is the floor.

Usage: python bench/bench_quadruped.py [--seconds 5]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time

import numpy as np
from orca_ros.examples import quadruped as quad
from orca_ros.sim import SimServer

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'peer'))

import qp_solvers  # noqa: E402


def run(solver: str, seconds: float, capture=None):
    robot = quad.make_robot()
    qc = quad.QuadrupedController(robot, solver)
    c = qc.controller
    home = np.array([0.0, 0.0, quad.STAND_HEIGHT])
    times, failed = [], []
    with SimServer(time_step=0.001) as server:
        sim, by_name = quad.insert_standing(server)
        gc.disable()
        try:
            for k in range(int(seconds / 0.001)):
                quad.state_from_sim(robot, sim, by_name)
                y = 0.03 * np.sin(2 * np.pi * 0.5 * k * 0.001)
                qc.set_base_target(home + [0, y, 0])
                t0 = time.perf_counter()
                ok = qc.update(k * 0.001, 0.001)
                times.append(time.perf_counter() - t0)
                if not ok:  # the fallback would apply: counted, reported
                    failed.append(k)
                if capture is not None and ok:
                    capture.append(qp_solvers.snapshot(c, robot))
                sim.set_joint_torque_command(c.get_joint_torque_command(), by_name)
                server.step()
        finally:
            gc.enable()
    run.problem = c.get_problem_at_level(0)
    return np.asarray(times[200:]) * 1e6, robot, failed


def floor(solver, captured, robot, problem):
    lay = problem.layout
    r = qp_solvers.time_floor(
        robot.model, captured, solver, lay.nx, problem.n_eq, problem.n_in, lay.variable_scale
    )
    return r['total'][200:] * 1e6


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--seconds', type=float, default=5.0)
    args = ap.parse_args(argv)
    print(
        f'update() timing, quadruped standing (42 QP variables), {args.seconds:g} s at 1 kHz '
        '(microseconds)'
    )
    print(
        f"{'solver':<9}{'median':>9}{'p99':>9}{'floor med':>11}{'floor p99':>11}"
        '  failed cycles (first ones)'
    )
    for solver in ('daqp', 'proxqp', 'osqp'):
        cap = []
        _, crobot, _ = run(solver, args.seconds, cap)  # the floor's QPs (times: with the copies)
        f = floor(solver, cap, crobot, run.problem)
        fl = f'{np.median(f):>11.1f}{np.percentile(f, 99):>11.1f}'
        ts, robot, failed = run(solver, args.seconds)  # timed without the capture's copies
        print(
            f'{solver:<9}{np.median(ts):>9.1f}{np.percentile(ts, 99):>9.1f}{fl}'
            f'  {len(failed)} {failed[:5]}'
        )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
