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
Node soak, the real-time benchmark: the node pair under a clock at 1 kHz for minutes.

pybullet_bridge (free running, 1 kHz) + orca_controller (its 1 kHz timer, the shipped
config/lwr_controller.yaml: the solve budget is the shipped default, one control period), as
deployed. bench/bench_node_loop.py, by contrast, runs the pair in lockstep without a clock: it
measures throughput, not real time.

Reports, from the controller's own diagnostics (loop periods measured inside the node over
non-overlapping windows of ``statistics_window`` cycles) and its /proc status:
  * resident memory (RSS) after warm-up and at the end: the growth must stay under 100 kB;
  * the control period (time between consecutive control cycles, each publishing one command):
    mean, p99, p99.9 and max per window, and their worst window;
  * the state-in to command-out latency (from the reception of the state a command answers to
    its publication): median and p99 per window;
  * cycles run vs wall time (achieved rate);
  * the solve budget in force, the solve time (last window's median and p99), and the QP failures
    and dropped levels during the soak (a cycle the budget cut short fails or drops a level).
Run on an idle machine for the period quantiles to mean anything (the README gives the latest
numbers).

Usage: python bench/bench_node_soak.py [--minutes 10] [--warmup 60] [--rate 1000]
"""

from __future__ import annotations

import argparse
import tempfile
import threading
import time

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs


def rss_kb(pid: int) -> int:
    with open(f'/proc/{pid}/status') as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    return 0


class DiagnosticsListener:
    """Keeps the controller's latest diagnostics values (a 5 Hz topic: negligible load)."""

    def __init__(self, domain: int):
        from diagnostic_msgs.msg import DiagnosticArray
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node('soak_probe', context=self.context)
        self.values: dict = {}
        self.lock = threading.Lock()
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diag, 10)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._stop = False
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self):
        while not self._stop and self.context.ok():
            self.executor.spin_once(timeout_sec=0.1)

    def _on_diag(self, msg):
        for st in msg.status:
            if 'whole-body controller' in st.name:
                with self.lock:
                    self.values = {kv.key: kv.value for kv in st.values}

    def latest(self) -> dict:
        with self.lock:
            return dict(self.values)

    def close(self):
        self._stop = True
        self.thread.join(timeout=2)
        self.node.destroy_node()
        self.context.try_shutdown()


def wait_for(cond, timeout: float, what: str):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return
        time.sleep(0.1)
    raise TimeoutError(f'timed out waiting for {what}')


def soak(minutes: float, warmup: float, rate: float, window_s: float = 10.0, extra=()) -> dict:
    domain = free_domain_id()
    procs = Procs(domain, tempfile.mkdtemp(prefix='orca_soak_'))
    window = int(rate * window_s)
    procs.start(
        'orca_ros.ros.pybullet_bridge',
        '-p',
        'mode:=free_running',
        '-p',
        f'rate:={rate}',
        '-p',
        'initial_positions:=[0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]',
        name='bridge',
    )
    ctrl = procs.start(
        'orca_ros.ros.controller_node',
        '--params-file',
        orca.share_path('config', 'lwr_controller.yaml'),
        '-p',
        'trigger:=timer',
        '-p',
        f'update_rate:={rate}',
        '-p',
        f'statistics_window:={window}',
        '-p',
        'diagnostics_rate:=1.0',
        *extra,
        name='controller',
    )
    diag = DiagnosticsListener(domain)
    windows = []
    try:
        wait_for(lambda: int(diag.latest().get('cycles', '0')) > 0, 120, 'the controller to run')
        time.sleep(warmup)
        rss0, t0 = rss_kb(ctrl.pid), time.monotonic()
        d0 = diag.latest()
        c0 = int(d0['cycles'])
        rss_trace = [rss0]
        end = t0 + minutes * 60.0
        while time.monotonic() < end:
            time.sleep(window_s)
            d = diag.latest()
            windows.append(
                [
                    float(d[k])
                    for k in (
                        'loop_period_mean_ms',
                        'loop_period_p99_ms',
                        'loop_period_p999_ms',
                        'loop_period_max_ms',
                        'state_to_command_median_ms',
                        'state_to_command_p99_ms',
                    )
                ]
            )
            rss_trace.append(rss_kb(ctrl.pid))
        d1 = diag.latest()
        c1, t1 = int(d1['cycles']), time.monotonic()
        alive = ctrl.poll() is None
    finally:
        diag.close()
        procs.stop()
    w = np.array(windows)
    return {
        'rss_after_warmup_kb': rss0,
        'rss_end_kb': rss_trace[-1],
        'rss_growth_kb': rss_trace[-1] - rss0,
        'rss_max_growth_kb': max(rss_trace) - rss0,
        'rate_hz': (c1 - c0) / (t1 - t0),
        'windows': len(w),
        'period_mean_ms': float(np.median(w[:, 0])),
        'p99_ms': float(np.median(w[:, 1])),
        'p999_ms': float(np.median(w[:, 2])),
        'worst_p99_ms': float(w[:, 1].max()),
        'worst_p999_ms': float(w[:, 2].max()),
        'max_ms': float(w[:, 3].max()),
        'latency_median_ms': float(np.median(w[:, 4])),
        'latency_p99_ms': float(np.median(w[:, 5])),
        'worst_latency_p99_ms': float(w[:, 5].max()),
        'alive': alive,
        'rss_trace': rss_trace,
        'budget': d1.get('solver_budget', '?'),
        'solver': d1.get('solver', '?'),
        'scheduling': d1.get('scheduling', '?'),
        'scheduling_refused': d1.get('scheduling_refused', ''),
        'solve_median_us': float(d1.get('solve_time_median_us', 'nan')),
        'solve_p99_us': float(d1.get('solve_time_p99_us', 'nan')),
        'qp_failures': int(d1.get('qp_failures', 0)) - int(d0.get('qp_failures', 0)),
        'dropped_levels': int(d1.get('dropped_levels', 0)) - int(d0.get('dropped_levels', 0)),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--minutes', type=float, default=10.0)
    ap.add_argument(
        '--warmup', type=float, default=60.0, help='seconds before the RSS reference is taken'
    )
    ap.add_argument('--rate', type=float, default=1000.0)
    ap.add_argument(
        '-p',
        dest='params',
        action='append',
        default=[],
        help='extra controller parameter NAME:=VALUE (e.g. manage_gc:=false), repeatable',
    )
    args = ap.parse_args(argv)
    r = soak(
        args.minutes, args.warmup, args.rate, extra=[x for p in args.params for x in ('-p', p)]
    )
    print(
        f'bridge + controller at {args.rate:.0f} Hz for {args.minutes:g} min (after '
        f'{args.warmup:g} s warm-up), '
        f"{r['windows']} windows of 10 s"
    )
    print(f"achieved rate {r['rate_hz']:.1f} Hz; controller alive at the end: {r['alive']}")
    refused = f" (refused: {r['scheduling_refused']})" if r['scheduling_refused'] else ''
    print(f"controller's scheduling: {r['scheduling']}{refused}")
    print(
        f"solver {r['solver']}, budget {r['budget']}; solve time (last window) median "
        f"{r['solve_median_us']:.1f} us, p99 {r['solve_p99_us']:.1f} us; after warm-up: "
        f"{r['qp_failures']} QP failures, {r['dropped_levels']} dropped levels"
    )
    print(
        f"RSS after warm-up {r['rss_after_warmup_kb']} kB, at the end {r['rss_end_kb']} kB: "
        'growth '
        f"{r['rss_growth_kb']} kB (max {r['rss_max_growth_kb']} kB; target <= 100)"
    )
    print(
        f"control period (median of windows): mean {r['period_mean_ms']:.3f} ms, p99 "
        f"{r['p99_ms']:.3f} ms "
        f"(target <= 1.2), p99.9 {r['p999_ms']:.3f} ms (target <= 2)"
    )
    print(
        f"state in to command out (median of windows): median {r['latency_median_ms']:.3f} ms, "
        f"p99 {r['latency_p99_ms']:.3f} ms (worst window's p99 {r['worst_latency_p99_ms']:.3f} ms)"
    )
    print(
        'RSS every 10 s (kB above the reference):',
        ' '.join(str(x - r['rss_after_warmup_kb']) for x in r['rss_trace']),
    )
    print(
        f"worst window: p99 {r['worst_p99_ms']:.3f} ms, p99.9 {r['worst_p999_ms']:.3f} ms, max "
        f"{r['max_ms']:.3f} ms"
    )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
