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
Lockstep throughput of the node pair: how fast bridge + controller step a simulation together.

pybullet_bridge (``mode: lockstep``) and orca_controller (``trigger: joint_state``) as separate
processes: the simulator publishes a state, the controller answers with one command, the simulator
steps one control period (2 ms or 1 ms simulated) and publishes the next state. Nothing waits for
a clock: the pair runs flat out, and the controller's solve budget is the lockstep default (1 s,
no real-time bound). A third process timestamps the states on arrival.

Reported per simulated period: steps per wall second, the wall time of one step (one round trip
state -> command -> simulator step; median, p99) and simulated time per wall second (how much
faster or slower than real time a lockstep simulation runs).

What it does not measure: real-time operation. A step time below the period shows headroom in the
round trip, not that a 1 kHz loop keeps its period with the shipped budget (one period) under a
clock; that is bench/bench_node_soak.py (free-running 1 kHz simulator, the controller's 1 kHz
timer, its own loop-period statistics).

Usage: python bench/bench_node_loop.py [--seconds 10]
"""

from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs  # noqa: E402
from orca_ros.ros.testing.probe import Probe  # noqa: E402


def run(rate: float, seconds: float):
    domain = free_domain_id()
    tmp = tempfile.mkdtemp()
    procs = Procs(domain, tmp)
    period = 1.0 / rate
    procs.start_arm(
        'lockstep',
        controller_args=('-p', f'update_rate:={rate}'),
        bridge_args=('-p', f'control_period:={period}'),
    )
    probe = Probe(domain)
    arrivals = []
    try:
        probe.wait_for(lambda: probe.sim_time() > 0.5, 60, 'the loop to run')
        orig = probe._on_state

        def stamped(m):
            arrivals.append(
                (time.perf_counter(), m.header.stamp.sec + m.header.stamp.nanosec * 1e-9)
            )
            orig(m)

        probe._on_state = stamped
        # re-route the subscription callback through the timestamping wrapper
        for sub in probe.node.subscriptions:
            if sub.topic_name == '/joint_states':
                sub.callback = stamped
        time.sleep(seconds)
    finally:
        probe.close()
        procs.stop()
    a = np.array(arrivals)
    wall = a[-1, 0] - a[0, 0]
    sim = a[-1, 1] - a[0, 1]
    periods = np.diff(a[:, 0])
    return {
        'steps_per_s': (len(a) - 1) / wall,
        'step_median_ms': np.median(periods) * 1e3,
        'step_p99_ms': np.percentile(periods, 99) * 1e3,
        'sim_per_wall': sim / wall,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--seconds', type=float, default=10.0)
    args = ap.parse_args(argv)
    print(
        f'lockstep bridge + controller, flat out (no clock; solve budget: the lockstep default, '
        f'1 s), {args.seconds:g} s per row; throughput, not real time (bench/bench_node_soak.py)'
    )
    print(
        f"{'sim period ms':>14}{'steps/s':>10}{'step med ms':>13}{'step p99 ms':>13}"
        f"{'sim/wall':>10}"
    )
    for rate in (500.0, 1000.0):
        r = run(rate, args.seconds)
        print(
            f"{1e3 / rate:>14.0f}{r['steps_per_s']:>10.0f}{r['step_median_ms']:>13.3f}"
            f"{r['step_p99_ms']:>13.3f}{r['sim_per_wall']:>10.2f}"
        )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
