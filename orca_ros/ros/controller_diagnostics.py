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
The controller node's ``/diagnostics`` (mixed into the node).

Level and reason from :mod:`.health`, plus the numbers a user asks for first (solver status and
time, loop period quantiles and jitter, RSS, active tasks).

A joint state older than ``state_timeout`` (0.5 s at least in lockstep) is an ERROR even when no
cycle runs to notice it (lockstep with a dead simulator). Parameters: ``diagnostics_rate`` [5 Hz];
``overrun_factor`` [1.5]: a loop period above this many nominal periods counts as an overrun (not
judged in lockstep, where the simulator sets the pace); ``error_warn_threshold`` [0.01 m] and
``error_warn_time`` [2 s]: a Cartesian task further than this from its target for longer is
reported (WARN), in the log too (at most once per ``error_warn_time`` per task).
"""

from __future__ import annotations

import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
import numpy as np

from .common import DEFAULT_QOS, param
from .health import assess, persistent_error_text, TaskErrorWatch
from .realtime import scheduling_text
from ..optim.diagnosis import diagnose
from ..utils.throttled_log import ThrottledLog

_LEVEL = {0: DiagnosticStatus.OK, 1: DiagnosticStatus.WARN, 2: DiagnosticStatus.ERROR}


class ControllerDiagnostics:
    def setup_diagnostics(self, rate: float) -> None:
        self.overrun_factor = float(param(self, 'overrun_factor', 1.5))
        self.error_watch = TaskErrorWatch(
            float(param(self, 'error_warn_threshold', 0.01)),
            float(param(self, 'error_warn_time', 2.0)),
        )
        self._say_error = ThrottledLog(self.get_logger(), period=self.error_watch.duration)
        self._diag_marks = (0, 0, 0)  # cycles, QP failures, dropped levels at the previous report
        self.pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', DEFAULT_QOS)
        self.diagnostic_level = DiagnosticStatus.WARN
        if rate > 0:
            self.create_timer(
                1.0 / rate, self.housekeeping.timer_callback(self._publish_diagnostics)
            )

    def loop_statistics(self):
        """
        Solve times and loop periods over the last ``statistics_window`` cycles.

        A job's slices: one partition of a window per slice (each a fraction of a 1 kHz loop's
        period, even on a large window); ``yield from`` returns the numbers.
        """
        sol, per = self.solve_times, self.loop_periods
        solve_median, solve_p99 = sol.quantiles((0.5, 0.99))
        yield
        period_median, period_p99, period_p999 = per.quantiles((0.5, 0.99, 0.999))
        yield
        latency_median, latency_p99 = self.latencies.quantiles((0.5, 0.99))
        yield
        jitter = np.abs(per.values() - self.period) if len(per) else np.zeros(1)
        jitter_p99 = float(np.percentile(jitter, 99) * 1e3)
        yield
        return {
            'solve_median_us': solve_median * 1e6,
            'solve_p99_us': solve_p99 * 1e6,
            'solve_max_us': sol.max() * 1e6,
            'period_mean_ms': per.mean() * 1e3,
            'period_median_ms': period_median * 1e3,
            'period_p99_ms': period_p99 * 1e3,
            'period_p999_ms': period_p999 * 1e3,
            'period_max_ms': per.max() * 1e3,
            'latency_median_ms': latency_median * 1e3,
            'latency_p99_ms': latency_p99 * 1e3,
            'jitter_p99_ms': jitter_p99,
        }

    def _publish_diagnostics(self):
        """
        Publish the report (a job: the numbers in slices, see :meth:`loop_statistics`).

        Its counters and its stamp are of one instant, the job's start: cycles run in the slices
        that follow are the next report's (a report whose cycle count was read later than its
        failure count told of more failures than cycles between two reports).
        """
        cycles, fails, dropped = (
            self.loop_periods.total,
            self.qp_failures,
            self.controller.dropped_levels,
        )
        solved, sent, relaxed, ran = (self.solve_times.total, self.output.sent,
                                      self.contacts_relaxed_cycles, self.loop_cycles)
        stamp = self.get_clock().now().to_msg()
        c0, f0, d0 = self._diag_marks
        self._diag_marks = (cycles, fails, dropped)
        now = time.monotonic()
        interval = now - getattr(self, '_diag_wall', now)
        self._diag_wall = now
        # lockstep: a paused simulator re-announces its state about every 0.25 s, which is not a
        # fault
        timeout = self.state_timeout if self.trigger == 'timer' else max(self.state_timeout, 0.5)
        age = time.monotonic() - self._state_wall if self._have_state else 0.0
        persistent = self.error_watch.persistent(self.now()) if self._have_state else []
        self._say_error.period = self.error_watch.duration  # a live parameter
        for name, norm, dur in persistent:
            self._say_error('warning', f'error:{name}', persistent_error_text(name, norm, dur))
        level, message = assess(
            have_state=self._have_state,
            state_age=age,
            state_timeout=timeout,
            safe_reason=self.output.reason,
            safe_cause=self.output.cause,
            qp_failures=fails - f0,
            last_failure=self.last_qp_failure,
            dropped_levels=dropped - d0,
            periods=self.loop_periods.latest(cycles - c0),
            nominal_period=self.period,
            check_periods=self.trigger == 'timer',
            overrun_factor=self.overrun_factor,
            interval=interval,
            persistent_errors=persistent,
        )
        st = DiagnosticStatus()
        st.name = f'{self.get_name()}: whole-body controller'
        st.hardware_id = self.robot.name
        st.level, st.message = _LEVEL[level], message
        self.diagnostic_level = st.level
        yield
        stats = yield from self.loop_statistics()
        active = [n for n, t in self.setup.tasks.items() if t.is_computing()]
        values = {
            'solver_status': self.controller.get_return_code().value,
            'solver': self.controller.solver.value,
            'resolution_strategy': self.controller.resolution_strategy.value,
            'update_rate_hz': f'{self.update_rate:g}',
            'trigger': self.trigger,
            'joints': ','.join(self.setup.joints),
            'solve_time_median_us': f"{stats['solve_median_us']:.1f}",
            'solve_time_p99_us': f"{stats['solve_p99_us']:.1f}",
            'loop_period_mean_ms': f"{stats['period_mean_ms']:.3f}",
            'loop_period_p99_ms': f"{stats['period_p99_ms']:.3f}",
            'loop_period_p999_ms': f"{stats['period_p999_ms']:.3f}",
            'loop_period_max_ms': f"{stats['period_max_ms']:.3f}",
            'loop_jitter_p99_ms': f"{stats['jitter_p99_ms']:.3f}",
            'state_to_command_median_ms': f"{stats['latency_median_ms']:.3f}",
            'state_to_command_p99_ms': f"{stats['latency_p99_ms']:.3f}",
            'cycles': str(solved),
            'loop_cycles': str(ran),  # with the cycles sent the safe command unsolved (stale)
            'qp_failures': str(fails),
            'commands_sent': str(sent),
            'contacts_relaxed_cycles': str(relaxed),
            'dropped_levels': str(dropped),
            'rss_kb': str(_rss_kb()),
            'solver_budget': self._budget_text(),
            'active_tasks': ','.join(active),
            'enabled': str(self._enabled),
            'qp_conflict': self.qp_conflict,
            # the process's scheduling as it is, and why a request was refused (realtime.py)
            'scheduling': scheduling_text(),
            'scheduling_refused': self.scheduling_refused,
        }
        st.values = [KeyValue(key=k, value=v) for k, v in values.items()]
        arr = DiagnosticArray()
        arr.header.stamp = stamp
        arr.status = [st]
        self.pub_diag.publish(arr)

    def _diagnose_failure(self) -> None:
        """Name the constraints that conflict (a few ms, once per failing spell)."""
        try:
            self.qp_conflict = diagnose(self.controller).text()
        except Exception as exc:  # noqa: BLE001 - the diagnosis must not make things worse
            self.qp_conflict = f'diagnosis failed: {type(exc).__name__}: {exc}'
        self.say('warning', 'diagnosis', f'QP failure diagnosis: {self.qp_conflict}')

    def _budget_text(self) -> str:
        budget, cap = self.controller.get_solver_budget()
        when = 'one period' if budget is None else f'{budget * 1e3:g} ms'
        return f"{when}, {'default' if cap is None else cap} iterations"


def _rss_kb() -> int:
    """Resident set size of this process in kB (Linux; 0 elsewhere)."""
    try:
        with open('/proc/self/status') as f:
            for line in f:
                if line.startswith('VmRSS:'):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0
