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
Bounded cycles on infeasible problems.

Every update() returns within the solver budget and reports failure.

Three infeasible problems, 1000 control cycles each, per solver (default budget: one control
period, 1 ms):
  * arm_limits     Panda (example-robot-data) holding against gravity with joint
                   accelerations limited to 1e-3 rad/s^2 and torques to 0.1 Nm (no torque
                   both holds the arm and respects the limits);
  * equalities     Panda with two contradictory equality constraints (joint 1
                   acceleration = +1 and = -1);
  * wrench         the quadruped (urdf/quadruped.urdf) on four point contacts whose normal
                   forces are capped at 2 N each, joints held still (accelerations within
                   1e-2 rad/s^2, so the trunk cannot fall): no admissible contact wrench
                   carries its weight.
Each failed cycle applies the fallback the controller node uses (orca_ros.safety.SafeCommand: the
last good command fading into gravity + damping). Printed per row: failures (must be all cycles),
return codes, the median and the maximum time of update() and of update() + fallback, the budget,
the cycles over budget, and whether every fallback command was finite and within the torque limits.

Usage: python bench/bench_infeasible.py [--cycles 1000] [--solvers daqp,proxqp,osqp]
"""

from __future__ import annotations

import argparse
import collections
import copy
import gc
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'peer'))

import orca_ros as orca  # noqa: E402
from orca_ros.constraint.generic_constraint import GenericConstraint  # noqa: E402
from orca_ros.safety import SafeCommand  # noqa: E402
import run_orca as R  # noqa: E402
import scenarios as S  # noqa: E402


class OppositeJointAccelerations(GenericConstraint):
    """Two equality rows on one joint's acceleration: = +a and = -a (contradictory for a != 0)."""

    kind = 'equality'

    def __init__(self, name: str, joint: int = 1, value: float = 1.0):
        super().__init__(name)
        self.joint, self.value = joint, value

    def rows(self) -> int:
        return 2

    def _update_constraint_function(self, current_time: float, dt: float) -> None:
        col = self.layout.joint_acc.start + self.joint
        self.C[:, col] = 1.0
        self.lb[0] = self.ub[0] = self.value
        self.lb[1] = self.ub[1] = -self.value


def build(kind: str, solver: str):
    if kind == 'wrench':
        sc = copy.deepcopy(S.SCENARIOS['quadruped'])
        sc['points']['fmax'] = 2.0
    else:
        sc = copy.deepcopy(S.SCENARIOS['panda'])
    robot, model, c, _, q, v = R.build(sc, solver)
    if kind == 'wrench':
        acc = c.add_constraint(orca.JointAccelerationLimitConstraint, 'acceleration_limit')
        acc.set_limits(-1e-2, 1e-2)
        acc.set_ramp_duration(0.0)
        acc.activate()
    elif kind == 'arm_limits':
        c.get_constraint('torque_limit').set_limits(-0.1, 0.1)
        acc = c.add_constraint(orca.JointAccelerationLimitConstraint, 'acceleration_limit')
        acc.set_limits(-1e-3, 1e-3)
        acc.set_ramp_duration(0.0)
        acc.activate()
    elif kind == 'equalities':
        eq = OppositeJointAccelerations('opposite')
        c.add_constraint(eq)
        eq.set_ramp_duration(0.0)
        eq.activate()
    return robot, c, q, v


def run(kind: str, solver: str, cycles: int, dt: float = S.DT) -> dict:
    robot, c, q, v = build(kind, solver)
    n = robot.get_nr_of_degrees_of_freedom()
    safe = SafeCommand(robot)
    last = np.zeros(n)
    budget = c.get_solver_budget()[0] or dt
    t_update, t_total = np.empty(cycles), np.empty(cycles)
    codes = collections.Counter()
    failures, fallback_ok = 0, True
    R.set_state(robot, q, v)
    c.update(0.0, dt)  # configuration cycle (workspaces set up, not time-bounded)
    gc.collect()
    gc.disable()
    try:
        for k in range(cycles):
            t = (k + 1) * dt
            R.set_state(robot, q, v)
            t0 = time.perf_counter()
            ok = c.update(t, dt)
            t1 = time.perf_counter()
            if ok:
                cmd = c.get_joint_torque_command()
                safe.reset()
            else:
                cmd = safe.compute(t, last, q[-n:], v[-n:])
                failures += 1
            t2 = time.perf_counter()
            codes[c.get_return_code().value] += 1
            fallback_ok &= bool(
                np.isfinite(cmd).all() and np.all(np.abs(cmd) <= safe.limit + 1e-9)
            )
            last = cmd
            t_update[k], t_total[k] = t1 - t0, t2 - t0
    finally:
        gc.enable()
    return {
        'failures': failures,
        'codes': dict(codes),
        'update_median_us': np.median(t_update) * 1e6,
        'update_max_us': t_update.max() * 1e6,
        'total_max_us': t_total.max() * 1e6,
        'budget_us': budget * 1e6,
        'over_budget': int(np.sum(t_update > budget)),
        'fallback_ok': fallback_ok,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--cycles', type=int, default=1000)
    ap.add_argument('--solvers', default='daqp,proxqp,osqp')
    args = ap.parse_args(argv)
    print(f'infeasible problems, {args.cycles} cycles each; times in microseconds')
    print(
        f"{'problem':<12}{'solver':>8}{'failed':>8}{'upd med':>9}{'upd max':>9}{'+fallbk':>9}"
        f"{'budget':>8}{'over':>6}{'fallback ok':>13}  return codes"
    )
    worst = 0.0
    for kind in ('arm_limits', 'equalities', 'wrench'):
        for solver in args.solvers.split(','):
            r = run(kind, solver, args.cycles)
            worst = max(worst, r['update_max_us'])
            codes = ', '.join(f'{k} x{v}' for k, v in sorted(r['codes'].items()))
            print(
                f"{kind:<12}{solver:>8}{r['failures']:>8}{r['update_median_us']:>9.1f}"
                f"{r['update_max_us']:>9.1f}"
                f"{r['total_max_us']:>9.1f}{r['budget_us']:>8.0f}{r['over_budget']:>6}"
                f"{str(r['fallback_ok']):>13}  {codes}"
            )
    print(f'maximum update() time over every cycle: {worst:.1f} us')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
