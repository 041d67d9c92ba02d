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
Where a control cycle's time goes.

per-section timing of Controller.update() on a bench_tsid scenario.

Sections, in cycle order: the state input (RobotModel.set_configuration), the layout (Pinocchio's
terms, the contacts' Jacobians, the torque map), each task's and constraint's update, the plan (row
weights, bounds), the Hessian/gradient build and the solve; then the whole update() for reference.
``--cprofile`` prints instead the functions with the most own time under cProfile (its overhead
inflates small functions).

Usage: python bench/profile_cycle.py {panda,quadruped,talos} [--cycles 3000] [--cprofile]
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'peer'))

import run_orca as R  # noqa: E402
import scenarios as S  # noqa: E402


def sections(c, robot, q, v, cycles: int) -> dict:
    pc = time.perf_counter
    acc: dict = {}

    def timed(key, f, *a):
        t0 = pc()
        r = f(*a)
        acc[key] = acc.get(key, 0.0) + pc() - t0
        return r

    dt = S.DT
    for k in range(cycles):
        t = (k + 1) * dt
        timed('state input', R.set_state, robot, q, v)
        timed('layout', c.layout.update)
        for obj in c._updated:
            timed(f"{type(obj).__name__} '{obj.name}'", obj.update, t, dt)
        timed('plan', c._plan.update)
        p = c._problems[0]
        timed('build', p.build)
        timed('solve', p.solve)
        R.set_state(robot, q, v)
        timed('= update() as a whole', c.update, t, dt)
    return {k: v / cycles * 1e6 for k, v in acc.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('scenario', choices=sorted(S.SCENARIOS))
    ap.add_argument('--cycles', type=int, default=3000)
    ap.add_argument('--cprofile', action='store_true')
    args = ap.parse_args(argv)
    robot, model, c, h, q, v = R.build(S.SCENARIOS[args.scenario])
    R.set_state(robot, q, v)
    c.update(0.0, S.DT)  # configuration cycle
    if args.cprofile:
        pr = cProfile.Profile()
        pr.enable()
        for k in range(args.cycles):
            R.set_state(robot, q, v)
            c.update((k + 1) * S.DT, S.DT)
        pr.disable()
        pstats.Stats(pr).sort_stats('tottime').print_stats(25)
        return 0
    res = sections(c, robot, q, v, args.cycles)
    print(f'{args.scenario}: mean time per cycle over {args.cycles} cycles (microseconds)')
    parts = 0.0
    for key, us in res.items():
        if not key.startswith('='):
            parts += us
        print(f'  {key:<48}{us:8.2f}')
    print(f'  {"(sum of the sections)":<48}{parts:8.2f}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
