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
QP solvers on the controller's own QPs: DAQP (the default), ProxQP, OSQP and PIQP.

The QPs are those of bench/peer/scenarios.py (Panda, the quadruped, Talos: the bench_tsid
scenarios), captured from the controller (default solver) closing the loop for 2 s at 1 kHz, in
the units and layout its solver receives (bench/peer/qp_solvers.py). Each solver then solves the
captured sequence warm-started, as in the loop: DAQP, ProxQP and OSQP through the controller's
back-ends with the controller's settings (no time budget), PIQP (not shipped: an interior-point
reference, no warm start) at eps_abs 1e-9.

Per solver and scenario: the solve alone and the *floor* (one Pinocchio computeAllTerms + the
solve: the least a Python controller on this stack spends per cycle with that solver), median and
p99 in microseconds; the floor relative to DAQP's; the mean iterations; failed solves; the largest
deviation from the controller's solution (relative to max(1, |x|_inf)).

Each (scenario, solver) runs in its own process (bench/peer/run_orca.py --floor --solver S),
interleaved round by round in alternating order, so that the machine's load hits all alike; the
figures are medians over rounds of each process's median / p99.

Usage: python bench/bench_solvers.py [--rounds 5] [--scenarios panda quadruped talos]
       [--solvers daqp proxqp osqp piqp] [--steps N]
"""

from __future__ import annotations

import argparse
import os
import sys

from bench_tsid import run as run_peer  # one process per (scenario, solver), its JSON line
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PEER = os.path.join(HERE, 'peer')
SOLVERS = ('daqp', 'proxqp', 'osqp', 'piqp')


def floor_process(scenario: str, solver: str, steps) -> dict:
    cmd = [sys.executable, 'run_orca.py', scenario, '--floor', '--solver', solver]
    if steps is not None:
        cmd += ['--steps', str(steps)]
    return run_peer(cmd)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--scenarios', nargs='+', default=['panda', 'quadruped', 'talos'])
    ap.add_argument('--solvers', nargs='+', default=list(SOLVERS), choices=SOLVERS)
    ap.add_argument('--steps', type=int, default=None)
    args = ap.parse_args(argv)
    res: dict = {}
    for r in range(args.rounds):
        order = args.solvers if r % 2 == 0 else args.solvers[::-1]
        for sc in args.scenarios:
            for s in order:
                res.setdefault((sc, s), []).append(floor_process(sc, s, args.steps))
        print(f'round {r + 1}/{args.rounds} done', file=sys.stderr)

    def med(sc, s, key):
        return float(np.median([o[key] for o in res[(sc, s)]]))

    print(
        f"the controller's QPs, microseconds (median over {args.rounds} interleaved rounds of "
        "each process's median and p99); floor = computeAllTerms + solve; x DAQP = floor / "
        "DAQP's floor"
    )
    print(
        f"{'scenario':<11}{'size':<14}{'solver':<8}{'solve':>8}{'p99':>8}{'floor':>8}{'p99':>8}"
        f"{'x DAQP':>8}{'iter':>7}{'fails':>6}{'max dev':>10}"
    )
    for sc in args.scenarios:
        o = res[(sc, args.solvers[0])][0]
        size = f"{o['nvar']}x({o['neq']}+{o['nin']})"
        ref = med(sc, 'daqp', 'median_us') if (sc, 'daqp') in res else float('nan')
        for s in args.solvers:
            outs = res[(sc, s)]
            fl = med(sc, s, 'median_us')
            print(
                f"{sc:<11}{size:<14}{s:<8}{med(sc, s, 'solve_median_us'):>8.1f}"
                f"{med(sc, s, 'solve_p99_us'):>8.1f}{fl:>8.1f}{med(sc, s, 'p99_us'):>8.1f}"
                f"{fl / ref:>8.2f}{med(sc, s, 'iterations_mean'):>7.1f}"
                f"{sum(x['failures'] for x in outs):>6}"
                f"{max(x['max_rel_dev'] for x in outs):>10.1e}"
            )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
