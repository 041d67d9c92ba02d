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
Floor: for the same QPs, a Pinocchio computeAllTerms call plus one warm-started dense ProxQP
update+solve (the least any Python controller on this stack can spend).

Usage: python bench/bench_update.py [--cycles 3000]
"""

from __future__ import annotations

import argparse
import gc
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
import pinocchio as pin
import proxsuite


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
                p = c.get_problem_at_level(0)
                capture.append(
                    (
                        q.copy(),
                        v.copy(),
                        p.H.copy(),
                        p.g.copy(),
                        p.C.copy(),
                        p.l.copy(),
                        p.u.copy(),
                        p.lbox.copy(),
                        p.ubox.copy(),
                    )
                )
            if moving:
                q, v = integrate(robot, q, v, c.get_joint_torque_command(), dt)
    finally:
        gc.enable()
    scenario.misses = misses
    return times


def floor(captured):
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    model, data = robot.model, robot.data
    nx, n_in = captured[0][2].shape[0], captured[0][4].shape[0]
    qp = proxsuite.proxqp.dense.QP(nx, 0, n_in, True)
    qp.settings.eps_abs = 1e-9
    qp.settings.eps_rel = 0.0
    qp.settings.verbose = False
    q, v, H, g, C, l, u, lb, ub = captured[0]
    qp.init(H, g, None, None, C, l, u, lb, ub)
    qp.solve()
    qp.settings.initial_guess = proxsuite.proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
    times = []
    gc.disable()
    for q, v, H, g, C, l, u, lb, ub in captured:
        t0 = time.perf_counter()
        pin.computeAllTerms(model, data, q, v)
        qp.update(H, g, None, None, C, l, u, lb, ub)
        qp.solve()
        times.append(time.perf_counter() - t0)
    gc.enable()
    return times


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--cycles', type=int, default=3000)
    args = ap.parse_args(argv)
    print(f'update() timing, lwr 7-DoF, {args.cycles} cycles each (microseconds)')
    print(
        f'{"scenario":<20}{"solver":<9}{"median":>9}{"p99":>9}{"misses":>8}{"floor med":>11}'
        f'{"floor p99":>11}'
    )
    for moving, name in ((False, 'simple_controller'), (True, 'closed_loop')):
        for solver in ('daqp', 'proxqp', 'osqp'):
            scenario(solver, 200, moving)  # warm-up (imports, first factorisations)
            cap = [] if solver == 'proxqp' else None
            med, p99 = _stats(scenario(solver, args.cycles, moving, capture=None))
            misses = scenario.misses
            fl = ''
            if solver == 'proxqp':
                scenario(solver, args.cycles, moving, capture=cap)
                fmed, fp99 = _stats(floor(cap))
                fl = f'{fmed:>11.1f}{fp99:>11.1f}'
            print(f'{name:<20}{solver:<9}{med:>9.1f}{p99:>9.1f}{misses:>8d}{fl}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
