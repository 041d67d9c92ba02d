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
Start-up of a controller with the compiled cycle: cold (empty kernel cache) and warm.

Each run is a fresh process that imports orca_ros, builds a scenario of bench/peer/scenarios.py
with default settings (the compiled cycle) and configures it (the kernels compile or load there,
never in a control cycle). Cold runs get an empty ``NUMBA_CACHE_DIR``; warm runs one filled by an
earlier run. Printed per scenario: import time, and construction time (robot, tasks, constraints,
configuration) cold and warm (median of the warm rounds), and the reference path's construction
(``compiled=False``) for comparison.

Usage: python bench/bench_startup.py [--rounds N] [--scenarios panda quadruped talos]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

CHILD = """
import sys, time
t0 = time.perf_counter()
import orca_ros as orca
sys.path.insert(0, {peer!r})
import run_orca as R, scenarios as S
t1 = time.perf_counter()
if {reference}:
    _init = orca.Controller.__init__
    orca.Controller.__init__ = lambda self, *a, **k: _init(self, *a, compiled=False, **k)
robot, model, c, h, q, v = R.build(S.SCENARIOS[{name!r}])
c.get_levels()
t2 = time.perf_counter()
assert (c.compiled_cycle is not None) != {reference}
print('TIMES', t1 - t0, t2 - t1)
"""


def run(name: str, cache: str, reference: bool = False) -> tuple[float, float]:
    code = CHILD.format(peer=os.path.join(HERE, 'peer'), name=name, reference=reference)
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    out = subprocess.run(
        [sys.executable, '-c', code], env=env, capture_output=True, text=True, check=True
    )
    line = [ln for ln in out.stdout.splitlines() if ln.startswith('TIMES')][0]
    imp, build = (float(x) for x in line.split()[1:])
    return imp, build


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--scenarios', nargs='+', default=['panda', 'quadruped', 'talos'])
    args = ap.parse_args(argv)
    print(f"{'scenario':10s} {'import':>8s} {'cold':>8s} {'warm':>8s} {'reference':>10s}  [s]")
    with tempfile.TemporaryDirectory() as root:
        for name in args.scenarios:
            cache = os.path.join(root, name)
            _, cold = run(name, cache)
            warm, imports, ref = [], [], []
            for _ in range(args.rounds):  # interleaved: warm compiled, then the reference
                imp, build = run(name, cache)
                warm.append(build)
                imports.append(imp)
                ref.append(run(name, cache, reference=True)[1])
            print(
                f'{name:10s} {statistics.median(imports):8.2f} {cold:8.2f} '
                f'{statistics.median(warm):8.2f} {statistics.median(ref):10.2f}'
            )
    return 0


if __name__ == '__main__':
    sys.exit(main())
