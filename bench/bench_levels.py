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
Cost of priority levels: Controller.update() on the arm with 1, 2 and 3 levels, per solver.

Scenario (lwr.urdf, closed loop on the rigid-body model from a bent posture,
torque/position/velocity limits): end-effector position task (level 0), elbow position task pulling
elsewhere (level 1), joint posture (level 2). Rows:
  * one_level_weighted: the same tasks in a single weighted QP (the baseline);
  * multi_level_weighted with 1, 2 and 3 levels (the first 1, 2 or 3 tasks);
  * generalized with priority 0.5 between every pair of levels (two QPs per level below the first).

Usage: python bench/bench_levels.py [--cycles 3000] [--rounds 5] [--solvers daqp,proxqp,osqp]
"""

from __future__ import annotations

import argparse
import gc
import time

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import (
    add_conflicting_stack,
    add_standard_constraints,
    integrate,
    STACK_Q0,
)


def build(strategy: str, solver: str, n_tasks: int, priority: float | None = None):
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_gravity(np.array([0.0, 0.0, -9.81]))
    robot.set_robot_state(STACK_Q0, np.zeros(7))
    c = orca.Controller('bench', robot, strategy, solver)
    add_conflicting_stack(c, n_tasks)
    add_standard_constraints(c)
    if priority is not None:
        names = [t.name for t in c.get_tasks()]
        for i, hi in enumerate(names):
            for lo in names[i + 1:]:
                c.set_priority(hi, lo, priority)
    c.activate_tasks_and_constraints()
    return robot, c


def run(strategy: str, solver: str, n_tasks: int, cycles: int, priority: float | None = None):
    robot, c = build(strategy, solver, n_tasks, priority)
    q, v, dt = STACK_Q0.copy(), np.zeros(7), 0.001
    times = []
    gc.disable()
    try:
        for k in range(cycles):
            robot.set_robot_state(q, v)
            t0 = time.perf_counter()
            ok = c.update(k * dt, dt)
            times.append(time.perf_counter() - t0)
            if not ok:
                raise RuntimeError(
                    f'{strategy} {solver}: no solution at cycle {k} ({c.get_return_code().value})'
                )
            q, v = integrate(robot, q, v, c.get_joint_torque_command(), dt)
    finally:
        gc.enable()
    ts = np.asarray(times) * 1e6
    return float(np.median(ts)), float(np.percentile(ts, 99)), c.dropped_levels


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--cycles', type=int, default=3000)
    ap.add_argument('--rounds', type=int, default=5, help='interleaved rounds (medians reported)')
    ap.add_argument('--solvers', default='daqp,proxqp,osqp')
    args = ap.parse_args(argv)
    solvers = args.solvers.split(',')
    rows = [('one_level_weighted', 3, None)]
    rows += [('multi_level_weighted', n, None) for n in (1, 2, 3)]
    rows += [('generalized', n, 0.5) for n in (2, 3)]
    print(
        f'update() timing with priority levels, lwr 7-DoF closed loop, {args.cycles} cycles per '
        f'row, median over {args.rounds} interleaved rounds (microseconds)'
    )
    results = {}
    for _ in range(args.rounds):  # interleaved: a busy spell of the machine hits every row alike
        for strategy, n, prio in rows:
            for solver in solvers:
                run(strategy, solver, n, 200, prio)  # warm-up
                results.setdefault((strategy, n, solver), []).append(
                    run(strategy, solver, n, args.cycles, prio)
                )
    print(f"{'strategy':<22}{'levels':>7}{'solver':>8}{'median':>9}{'p99':>9}{'held':>6}")
    med = {}
    for (strategy, n, solver), runs in results.items():
        med[(strategy, n, solver)] = float(np.median([r[0] for r in runs]))
        p99 = float(np.median([r[1] for r in runs]))
        held = int(max(r[2] for r in runs))
        levels = 1 if strategy == 'one_level_weighted' else n
        print(f'{strategy:<22}{levels:>7}{solver:>8}{med[(strategy, n, solver)]:>9.1f}'
              f'{p99:>9.1f}{held:>6}')
    # each added strict level <= 0.35x a one-level cycle (the same tasks), read two ways;
    # GENERALIZED with 3 levels <= 2x the one-level cycle
    for solver in solvers:
        one = med[('one_level_weighted', 3, solver)]
        multi = [med[('multi_level_weighted', n, solver)] for n in (1, 2, 3)]
        same = (multi[2] - one) / 2.0 / one
        grow = [(multi[k] - multi[k - 1]) / multi[0] for k in (1, 2)]
        print(
            f'{solver}: the same 3 tasks in 3 levels instead of 1: {same:.2f}x the one-level '
            f'cycle per added level; a level added with its task: {grow[0]:.2f}x, {grow[1]:.2f}x '
            'of the 1-task cycle'
        )
        gen = med[('generalized', 3, solver)] / one
        print(f'{solver}: GENERALIZED, 3 levels (priorities 0.5): {gen:.2f}x the one-level cycle')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
