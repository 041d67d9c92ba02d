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
The controller node's own CPU time per control cycle at 1 kHz: solved cycles and failing ones.

The shipped arm (config/lwr_controller.yaml: 1 kHz timer, DAQP, one period of solve budget)
beside the free-running 1 kHz bridge, as deployed. Two scenarios, run one after the other in each
round (interleaved, so a change of the machine's load falls on both):
  * solved: the shipped YAML as it is, the arm holding its start;
  * failing: torque limits of 0.1 Nm and velocity limits of 1 mrad/s, so every QP is infeasible and
    every cycle sends the safe command (test/test_ros_budget.py's scenario).
Over ``--cycles`` cycles after a warm-up: the CPU time of the node's control thread and its time
waiting for a CPU (Linux schedstat), per cycle; the solve time the node reports (median).

Target: the node's own work takes at most 0.6 of the period (0.6 ms at 1 kHz), whether its QP
is solved or fails. How much of the period the work takes depends on the CPU (a slow CI machine
took 1.07 of it, failing, on Python 3.12), so the figure is a benchmark's; test_ros_budget.py
asserts what holds on any machine where the work fits (lost periods are ones the machine took).

Usage: python bench/bench_node_cpu.py [--rounds 3] [--cycles 3000]
"""

from __future__ import annotations

import argparse
import tempfile

import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
from orca_ros.utils.schedstat import thread_schedstat

TARGET = 0.6e-3  # s of CPU per cycle at 1 kHz
FAILING = ('-p', 'constraints.torque_limit.max:=0.1',
           '-p', 'constraints.velocity_limit.max:=0.001')


def _sample(probe, pid):
    """Wait for a fresh diagnostics report; return its cycle count, solve median, schedstat."""
    before = probe.diagnostics.get('cycles')
    probe.wait_for(lambda: probe.diagnostics.get('cycles') != before, 30, 'a diagnostics report')
    with probe.lock:
        d = dict(probe.diagnostics)
    return int(d['cycles']), int(d.get('qp_failures', 0)), d, thread_schedstat(pid)


def run(scenario: str, cycles: int) -> dict:
    domain = free_domain_id()
    procs = Procs(domain, tempfile.mkdtemp())
    procs.start_arm('free_running', controller_args=FAILING if scenario == 'failing' else (),
                    bridge_args=('-p', 'rate:=1000.0'))
    probe = Probe(domain)
    try:
        pid = procs.procs[1][0].pid
        probe.wait_for(lambda: int(probe.diagnostics.get('cycles', 0)) > 2000, 120, 'warm-up')
        n0, f0, _, s0 = _sample(probe, pid)
        probe.wait_for(lambda: int(probe.diagnostics.get('cycles', 0)) > n0 + cycles, 120,
                       f'{cycles} cycles')
        n1, f1, d1, s1 = _sample(probe, pid)
    finally:
        probe.close()
        procs.stop()
    if s0 is None or s1 is None:
        raise SystemExit('no /proc/<pid>/task/<pid>/schedstat on this kernel')
    n = n1 - n0
    return {
        'cpu': (s1[0] - s0[0]) / n, 'wait': (s1[1] - s0[1]) / n, 'failed': (f1 - f0) / n,
        'solve_us': float(d1['solve_time_median_us']),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    ap.add_argument('--rounds', type=int, default=3)
    ap.add_argument('--cycles', type=int, default=3000)
    args = ap.parse_args()
    results: dict = {'solved': [], 'failing': []}
    for r in range(args.rounds):
        for scenario in results:
            got = run(scenario, args.cycles)
            results[scenario].append(got)
            print(f"round {r + 1} {scenario:8s}: CPU {got['cpu'] * 1e3:.3f} ms/cycle, waited "
                  f"{got['wait'] * 1e3:.3f} ms/cycle, {got['failed']:.0%} failed, solve median "
                  f"{got['solve_us']:.1f} us", flush=True)
    print(f'\nmedians over {args.rounds} rounds (target: CPU <= {TARGET * 1e3:.1f} ms per cycle)')
    for scenario, rs in results.items():
        cpu = float(np.median([x['cpu'] for x in rs]))
        verdict = 'met' if cpu <= TARGET else 'NOT met'
        solve = float(np.median([x['solve_us'] for x in rs]))
        print(f'  {scenario:8s}: CPU {cpu * 1e3:.3f} ms/cycle ({verdict}), solve median '
              f'{solve:.1f} us')


if __name__ == '__main__':
    main()
