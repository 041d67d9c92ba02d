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
Compare orca_ros with TSID (and PlaCo) on the same URDF files and the same tasks.

TSID is the peer: C++ core, Python bindings. PlaCo's DynamicsSolver (C++ core, Python bindings,
its own Pinocchio) is a second peer; the ratios stay relative to TSID.

Scenarios (bench/peer/scenarios.py): the Panda arm (example-robot-data, 9 DoF: 6-D end-effector
task following a moving point, posture, torque/position/velocity limits), the project's quadruped
(4 point contacts with 4-face pyramids, trunk 6-D task, posture, torque limits) and Talos
(example-robot-data, 38 DoF: both soles as rectangular surface contacts, CoM sway +-5 cm at 0.5 Hz,
posture). All controllers close the same kinematic loop for 2 s at 1 kHz and report per-step time
(state in -> torques out) and the final task error (a lag: the references carry no feed-forward).
The floor is Pinocchio's computeAllTerms + one warm-started solve of orca_ros's QP of each step
(captured, in the solver's units and layout): what any Python controller on this stack spends at
least with that solver. It is printed for each of the controller's solvers (--floor-solvers);
the one of the default solver (DAQP), marked *, is the floor: floor / TSID compares like with like
(bench/bench_solvers.py times the solvers alone on the same QPs).

Each (scenario, implementation) runs in its own process, interleaved round by round so that the
machine's load hits all of them alike; the ratios are of the medians over rounds. TSID runs in a
side venv (Python 3.13, built or reused by bench/tsid_venv.sh), PlaCo in another (Python 3.11,
bench/placo_venv.sh; skipped with --no-placo or when that venv cannot be made). PlaCo's sole
contacts are 6-D wrenches (CoP in the rectangle) where TSID's and orca_ros's are forces at the 4
corners, and it has no maximum normal force: bench/peer/run_placo.py says how each scenario maps
onto it.

Usage: python bench/bench_tsid.py [--rounds 5] [--scenarios panda quadruped talos] [--steps N]
       [--solvers daqp] [--floor-solvers daqp proxqp osqp] [--no-placo]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PEER = os.path.join(HERE, 'peer')


def tsid_python() -> str:
    out = subprocess.run(
        ['bash', os.path.join(HERE, 'tsid_venv.sh')], check=True, capture_output=True, text=True
    )
    return out.stdout.strip().splitlines()[-1]


def placo_python() -> str | None:
    """Return the python of PlaCo's venv (bench/placo_venv.sh), or None if it can't be made."""
    try:
        out = subprocess.run(
            ['bash', os.path.join(HERE, 'placo_venv.sh')],
            check=True,
            capture_output=True,
            text=True,
        )
    except subprocess.CalledProcessError as e:
        tail = e.stderr.strip().splitlines()[-1:] or ['?']
        print(f'PlaCo skipped: its venv could not be made ({tail[0]})', file=sys.stderr)
        return None
    return out.stdout.strip().splitlines()[-1]


def run(cmd):
    env = dict(os.environ, PYTHONWARNINGS='ignore')
    out = subprocess.run(cmd, cwd=PEER, check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--scenarios', nargs='+', default=['panda', 'quadruped', 'talos'])
    ap.add_argument('--steps', type=int, default=None)
    ap.add_argument(
        '--solvers', nargs='+', default=[None], help='orca_ros solvers (default: its default)'
    )
    ap.add_argument(
        '--floor-solvers',
        nargs='+',
        default=['daqp', 'proxqp', 'osqp'],
        help='solvers whose floor is timed (the default solver, DAQP, is the floor)',
    )
    ap.add_argument('--no-placo', action='store_true', help='do not run PlaCo (the second peer)')
    args = ap.parse_args(argv)
    tpy = tsid_python()
    steps = [] if args.steps is None else ['--steps', str(args.steps)]
    impls = [('tsid', [tpy, 'run_tsid.py'])]
    ppy = None if args.no_placo else placo_python()
    if ppy is not None:
        impls.append(('placo', [ppy, 'run_placo.py']))
    for s in args.solvers:
        impls.append(
            (
                f"orca_{s or 'default'}",
                [sys.executable, 'run_orca.py'] + ([] if s is None else ['--solver', s]),
            )
        )
    for s in args.floor_solvers:
        impls.append((f'floor_{s}', [sys.executable, 'run_orca.py', '--floor', '--solver', s]))
    res = {}
    for r in range(args.rounds):
        order = impls if r % 2 == 0 else impls[::-1]
        for sc in args.scenarios:
            for name, cmd in order:
                out = run(cmd + [sc] + steps)
                res.setdefault((sc, name), []).append(out)
        print(f'round {r + 1}/{args.rounds} done', file=sys.stderr)
    print(
        f'per-step time, microseconds (median over {args.rounds} interleaved rounds of each '
        "process's median "
        f'and p99); ratio = row / TSID; floor = computeAllTerms + one warm solve of the same '
        "QP (* the default solver's: the floor)"
    )
    print(
        f"{'scenario':<10}{'impl':<14}{'median':>9}{'p99':>9}{'ratio':>8}{'failures':>10}  final "
        'task error (m)'
    )
    for sc in args.scenarios:
        ref = float(np.median([o['median_us'] for o in res[(sc, 'tsid')]]))
        ref_err = res[(sc, 'tsid')][-1].get('errors', {})
        for name, _ in impls:
            outs = res[(sc, name)]
            med = float(np.median([o['median_us'] for o in outs]))
            p99 = float(np.median([o['p99_us'] for o in outs]))
            fails = sum(o.get('failures', 0) for o in outs)
            err = outs[-1].get('errors', {})
            rel = ''
            if err and ref_err:
                rel = ' '.join(
                    f'{k} {v:.5f} ({100 * (v - ref_err[k]) / ref_err[k]:+.1f} % vs TSID)'
                    for k, v in err.items()
                    if k in ref_err and name != 'tsid'
                )
                if name == 'tsid':
                    rel = ' '.join(f'{k} {v:.5f}' for k, v in err.items())
            if outs[-1].get('default'):
                name += ' *'
            print(f'{sc:<10}{name:<14}{med:>9.1f}{p99:>9.1f}{med / ref:>8.2f}{fails:>10}  {rel}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
