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
Node-level loop.

pybullet_bridge + orca_controller as separate processes in lockstep (one simulated control period
per command), at 500 Hz and 1 kHz nominal.

Reports the achieved loop rate (commands per wall second), the wall-clock period between
consecutive states (median, p99) and the simulated-time ratio.

A rate at or above nominal with p99 period within 2x nominal means the pair sustains that control
rate in real time. Usage: python bench/bench_node_loop.py [--seconds 10]
"""

from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np
from orca_ros.ros.launch_free import free_domain_id, Procs  # noqa: E402
from orca_ros.ros.probe import Probe  # noqa: E402


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
        'rate': (len(a) - 1) / wall,
        'period_median_ms': np.median(periods) * 1e3,
        'period_p99_ms': np.percentile(periods, 99) * 1e3,
        'sim_per_wall': sim / wall,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--seconds', type=float, default=10.0)
    args = ap.parse_args(argv)
    print(f'lockstep bridge + controller, {args.seconds:.0f} s per row')
    print(
        f'{"nominal":>8}{"achieved Hz":>13}{"period med ms":>15}{"period p99 ms":>15}'
        f'{"sim/wall":>10}'
    )
    for rate in (500.0, 1000.0):
        r = run(rate, args.seconds)
        print(
            f'{rate:>8.0f}{r["rate"]:>13.0f}{r["period_median_ms"]:>15.3f}'
            f'{r["period_p99_ms"]:>15.3f}'
            f'{r["sim_per_wall"]:>10.2f}'
        )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
