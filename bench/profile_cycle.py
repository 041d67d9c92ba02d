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

per-section timing of Controller.update() on a bench_tsid scenario, in the closed loop of
bench/bench_tsid.py: every cycle the references move, the controller gets a new state and the
state is advanced with its solution (v += dt * dv, q = integrate(q, dt * v), as both controllers
of bench_tsid do), so each solve is warm-started from the previous cycle's QP, not re-solving the
same one.

Sections, in cycle order: the state input (RobotModel.set_configuration), the layout (Pinocchio's
terms, the contacts' Jacobians, the torque map), each task's and constraint's update, the plan (row
weights, bounds), the Hessian/gradient build and the solve; the rest of update() (budget, result,
command). They are timed inside the real update() (each section's method wrapped: ~0.1 us added
per section). Beside it, a second controller without the wrappers runs the same cycles (same
states and references, the order alternating cycle by cycle): its update() is the reference time.
``--cprofile`` prints instead the functions with the most own time under cProfile (its overhead
inflates small functions), on the same closed loop.

Usage: python bench/profile_cycle.py {panda,quadruped,talos} [--cycles N] [--cprofile]
       (N: default the scenario's 2 s, 2000 cycles; the first 100 are not counted)
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import os
import pstats
import sys
import time

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'peer'))

import run_orca as R  # noqa: E402
import scenarios as S  # noqa: E402

SKIP = 100  # warm-up cycles not counted


class Sections:
    """Times the sections of a controller's update() by wrapping their methods on the instances."""

    def __init__(self, c):
        self.acc: dict = {}
        self._wrap(c.layout, 'update', 'layout')
        cycle = c.cycle
        for obj in cycle.objects:
            self._wrap(obj, 'update', f"{type(obj).__name__} '{obj.name}'")
        self._wrap(cycle.plan, 'update', 'plan')
        for p in cycle.levels.problems:
            self._wrap(p, 'build', 'build')
            self._wrap(p, 'solve', 'solve')

    def _wrap(self, obj, method, key):
        f = getattr(obj, method)
        pc = time.perf_counter
        acc = self.acc
        acc.setdefault(key, 0.0)

        def timed(*a):
            t0 = pc()
            r = f(*a)
            acc[key] += pc() - t0
            return r

        setattr(obj, method, timed)

    def total(self) -> float:
        return sum(self.acc.values())

    def reset(self) -> None:
        for key in self.acc:
            self.acc[key] = 0.0


def closed_loop(model, q, v, n: int, cycle_fn) -> None:
    """Run n cycles of the closed loop; ``cycle_fn(k, t, q, v)`` runs one and returns dv."""
    for k in range(n):
        t = k * S.DT
        dv = cycle_fn(k, t, q, v)
        v = v + S.DT * dv
        q = pin.integrate(model, q, S.DT * v)


def _configured(sc):
    robot, model, c, h, q, v = R.build(sc)
    R.set_state(robot, q, v)
    c.update(0.0, S.DT)  # configuration cycle (workspaces set up); the loop starts over at t=0
    return robot, model, c, h, q, v


def profile_sections(name: str, cycles: int | None):
    sc = S.SCENARIOS[name]
    n = cycles or S.steps(sc)
    ctl = {key: _configured(sc) for key in ('timed', 'plain')}
    model, q0, v0 = ctl['timed'][1], ctl['timed'][4], ctl['timed'][5]
    sec = Sections(ctl['timed'][2])
    tot = {'state input': 0.0, 'timed': 0.0, 'plain': 0.0}
    iters = []
    dev = [0.0]
    pc = time.perf_counter

    def cycle(k, t, q, v):
        if k == SKIP:  # warm-up over: count from here
            sec.reset()
            for key in tot:
                tot[key] = 0.0
        for key in ('timed', 'plain') if k % 2 == 0 else ('plain', 'timed'):
            robot, _, c, h, _, _ = ctl[key]
            R._set_refs(h, t)
            t0 = pc()
            R.set_state(robot, q, v)
            t1 = pc()
            c.update(t, S.DT)
            c.get_joint_torque_command()
            t2 = pc()
            if key == 'timed':
                tot['state input'] += t1 - t0
                tot['timed'] += t2 - t1
            else:
                tot['plain'] += t2 - t0
        a, b = ctl['timed'][2], ctl['plain'][2]
        iters.append(a._problems[0].backend.iterations)
        x = a.get_solution()
        dev[0] = max(dev[0], float(np.max(np.abs(x - b.get_solution()))))
        return x[: model.nv]

    gc.collect()
    gc.disable()
    closed_loop(model, q0, v0, n, cycle)
    gc.enable()
    m = max(n - SKIP, 1)
    res = {'state input': tot['state input'] / m * 1e6}
    res.update({k: v / m * 1e6 for k, v in sec.acc.items()})
    res['rest of update() and the command'] = (tot['timed'] - sec.total()) / m * 1e6
    return res, tot['plain'] / m * 1e6, float(np.mean(iters[SKIP:])), dev[0], n


def profile_cprofile(name: str, cycles: int | None) -> None:
    sc = S.SCENARIOS[name]
    robot, model, c, h, q, v = _configured(sc)
    pr = cProfile.Profile()

    def cycle(k, t, q, v):
        R._set_refs(h, t)
        pr.enable()
        R.set_state(robot, q, v)
        c.update(t, S.DT)
        c.get_joint_torque_command()
        pr.disable()
        return c.get_solution()[: model.nv]

    closed_loop(model, q, v, cycles or S.steps(sc), cycle)
    pstats.Stats(pr).sort_stats('tottime').print_stats(25)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('scenario', choices=sorted(S.SCENARIOS))
    ap.add_argument('--cycles', type=int, default=None)
    ap.add_argument('--cprofile', action='store_true')
    args = ap.parse_args(argv)
    if args.cprofile:
        profile_cprofile(args.scenario, args.cycles)
        return 0
    res, plain, iters, dev, n = profile_sections(args.scenario, args.cycles)
    print(
        f'{args.scenario}: closed loop, mean time per cycle over cycles {SKIP}-{n - 1} '
        '(microseconds)'
    )
    for key, us in res.items():
        print(f'  {key:<64}{us:8.2f}')
    print(f"  {'(sum: state input + update() with the wrappers)':<64}{sum(res.values()):8.2f}")
    print(f"  {'= state input + update(), without the wrappers':<64}{plain:8.2f}")
    print(
        f"  solver iterations per cycle (mean) {iters:.2f}; the two controllers' solutions "
        f'differ by at most {dev:.1e}'
    )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
