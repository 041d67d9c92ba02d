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
Time of Controller.update() on the arm, per solver, against the floor of the same run.

Scenarios (lwr.urdf, one Cartesian task on link_7 with the reference gains,
torque/position/velocity limits):
  * simple_controller: the reference's first example -- a constant robot state (as a robot holding
    still);
  * closed_loop: the arm's dynamics integrated from q = 0 towards its target (moving state, active
    velocity limits), update() timed only.
Floor, per solver: for the QPs of that solver's run (captured in a second run, in the solver's
units and layout: bench/peer/qp_solvers.py), a Pinocchio computeAllTerms call plus one
warm-started solve by that solver with the controller's settings (the least any Python controller
on this stack can spend with it). The default solver's (DAQP) is the floor.

Usage: python bench/bench_update.py [--cycles 3000]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import (
    add_standard_constraints,
    integrate,
    make_cartesian_servo,
    make_controller,
    make_robot,
)
from orca_ros.examples.simulating_results import reachable_target

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'peer'))

import qp_solvers  # noqa: E402


def _stats(ts):
    ts = np.asarray(ts) * 1e6
    return float(np.median(ts)), float(np.percentile(ts, 99))


def scenario(solver: str, cycles: int, moving: bool, capture=None):
    robot, state = make_robot(orca.default_urdf_path())
    c = make_controller(robot, solver)
    target = orca.make_transform(reachable_target(robot), np.eye(3))
    c.add_task(orca.CartesianTask, 'CartTask_EE').set_servo_controller(
        make_cartesian_servo('link_7', target)
    )
    add_standard_constraints(c)
    c.activate_tasks_and_constraints()
    q, v = state.joint_pos.copy(), state.joint_vel.copy()
    dt = 0.001
    times = []
    misses = 0  # cycles the default budget (one 1 ms period) cut short: the fallback would apply
    gc.disable()
    try:
        for k in range(cycles):
            robot.set_robot_state(q, v)
            t0 = time.perf_counter()
            ok = c.update(k * dt, dt)
            times.append(time.perf_counter() - t0)
            if not ok:
                misses += 1
                continue
            if capture is not None:
                capture.append(qp_solvers.snapshot(c, robot))
            if moving:
                q, v = integrate(robot, q, v, c.get_joint_torque_command(), dt)
    finally:
        gc.enable()
    scenario.misses = misses
    scenario.problem = c.get_problem_at_level(0)
    scenario.model = robot.model
    return times


def floor(solver, captured, problem, model):
    lay = problem.layout
    r = qp_solvers.time_floor(
        model, captured, solver, lay.nx, problem.n_eq, problem.n_in, lay.variable_scale
    )
    return r['total']


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--cycles', type=int, default=3000)
    args = ap.parse_args(argv)
    print(
        f'update() timing, lwr 7-DoF, {args.cycles} cycles each (microseconds); floor: '
        "computeAllTerms + the row's solver on the same QPs"
    )
    print(
        f"{'scenario':<20}{'solver':<9}{'median':>9}{'p99':>9}{'misses':>8}{'floor med':>11}"
        f"{'floor p99':>11}"
    )
    for moving, name in ((False, 'simple_controller'), (True, 'closed_loop')):
        for solver in ('daqp', 'proxqp', 'osqp'):
            scenario(solver, 200, moving)  # warm-up (imports, first factorisations)
            med, p99 = _stats(scenario(solver, args.cycles, moving, capture=None))
            misses = scenario.misses
            cap = []
            scenario(solver, args.cycles, moving, capture=cap)  # untimed: the floor's QPs
            fmed, fp99 = _stats(floor(solver, cap, scenario.problem, scenario.model))
            print(
                f'{name:<20}{solver:<9}{med:>9.1f}{p99:>9.1f}{misses:>8d}{fmed:>11.1f}'
                f'{fp99:>11.1f}'
            )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
