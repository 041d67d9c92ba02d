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
The controller node's ``/diagnostics`` (a part of the node).

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

from .common import DEFAULT_QOS, param
from .health import assess, persistent_error_text, TaskErrorWatch
from .realtime import scheduling_text
from ..optim.diagnosis import diagnose
from ..utils.throttled_log import ThrottledLog

_LEVEL = {0: DiagnosticStatus.OK, 1: DiagnosticStatus.WARN, 2: DiagnosticStatus.ERROR}


class ControllerDiagnostics:
    """
    The controller node's ``/diagnostics`` report: a part of the node (see the module).

    ``node`` makes the publisher and the timer and gives what the report tells: its loop
    statistics (``stats``), controller, command output, configuration, clock, measured state
    (``have_state``, ``state.wall``), activation (``activation.enabled``), timing settings
    (``period``, ``update_rate``, ``trigger``, ``state_timeout``) and ``scheduling_refused``.
    """

    def __init__(self, node, rate: float):
        self.node = node
        self.overrun_factor = float(param(node, 'overrun_factor', 1.5))
        self.error_watch = TaskErrorWatch(
            float(param(node, 'error_warn_threshold', 0.01)),
            float(param(node, 'error_warn_time', 2.0)),
        )
        self._say_error = ThrottledLog(node.get_logger(), period=self.error_watch.duration)
        self._marks = (0, 0, 0)  # cycles, QP failures, dropped levels at the previous report
        self._wall = None  # wall time of the previous report
        self.publisher = node.create_publisher(DiagnosticArray, '/diagnostics', DEFAULT_QOS)
        self.level = DiagnosticStatus.WARN
        if rate > 0:
            job = node.housekeeping.timer_callback(self.publish_diagnostics)
            node.create_timer(1.0 / rate, job)

    def publish_diagnostics(self):
        """
        Publish the report (a job: the numbers in slices, see :meth:`.LoopStatistics.summary`).

        Its counters and its stamp are of one instant, the job's start: cycles run in the slices
        that follow are the next report's (a report whose cycle count was read later than its
        failure count told of more failures than cycles between two reports).
        """
        node = self.node
        stats, controller, output = node.stats, node.controller, node.output
        cycles, fails, dropped = (
            stats.loop_periods.total,
            stats.qp_failures,
            controller.dropped_levels,
        )
        solved, sent, relaxed, ran = (stats.solve_times.total, output.sent,
                                      stats.contacts_relaxed_cycles, stats.loop_cycles)
        stamp = node.get_clock().now().to_msg()
        c0, f0, d0 = self._marks
        self._marks = (cycles, fails, dropped)
        now = time.monotonic()
        interval = now - (now if self._wall is None else self._wall)
        self._wall = now
        # lockstep: a paused simulator re-announces its state about every 0.25 s, which is not a
        # fault
        timeout = node.state_timeout if node.trigger == 'timer' else max(node.state_timeout, 0.5)
        age = time.monotonic() - node.state.wall if node.have_state else 0.0
        persistent = self.error_watch.persistent(node.now()) if node.have_state else []
        self._say_error.period = self.error_watch.duration  # a live parameter
        for name, norm, dur in persistent:
            self._say_error('warning', f'error:{name}', persistent_error_text(name, norm, dur))
        level, message = assess(
            have_state=node.have_state,
            state_age=age,
            state_timeout=timeout,
            safe_reason=output.reason,
            safe_cause=output.cause,
            qp_failures=fails - f0,
            last_failure=stats.last_qp_failure,
            dropped_levels=dropped - d0,
            periods=stats.loop_periods.latest(cycles - c0),
            nominal_period=node.period,
            check_periods=node.trigger == 'timer',
            overrun_factor=self.overrun_factor,
            interval=interval,
            persistent_errors=persistent,
        )
        st = DiagnosticStatus()
        st.name = f'{node.get_name()}: whole-body controller'
        st.hardware_id = node.robot.name
        st.level, st.message = _LEVEL[level], message
        self.level = st.level
        yield
        numbers = yield from stats.summary(node.period)
        active = [n for n, t in node.setup.tasks.items() if t.is_computing()]
        values = {
            'solver_status': controller.get_return_code().value,
            'solver': controller.solver.value,
            'resolution_strategy': controller.resolution_strategy.value,
            'update_rate_hz': f'{node.update_rate:g}',
            'trigger': node.trigger,
            'joints': ','.join(node.setup.joints),
            'solve_time_median_us': f"{numbers['solve_median_us']:.1f}",
            'solve_time_p99_us': f"{numbers['solve_p99_us']:.1f}",
            'loop_period_mean_ms': f"{numbers['period_mean_ms']:.3f}",
            'loop_period_p99_ms': f"{numbers['period_p99_ms']:.3f}",
            'loop_period_p999_ms': f"{numbers['period_p999_ms']:.3f}",
            'loop_period_max_ms': f"{numbers['period_max_ms']:.3f}",
            'loop_jitter_p99_ms': f"{numbers['jitter_p99_ms']:.3f}",
            'state_to_command_median_ms': f"{numbers['latency_median_ms']:.3f}",
            'state_to_command_p99_ms': f"{numbers['latency_p99_ms']:.3f}",
            'cycles': str(solved),
            'loop_cycles': str(ran),  # with the cycles sent the safe command unsolved (stale)
            'qp_failures': str(fails),
            'commands_sent': str(sent),
            'contacts_relaxed_cycles': str(relaxed),
            'dropped_levels': str(dropped),
            'rss_kb': str(_rss_kb()),
            'solver_budget': _budget_text(controller),
            'active_tasks': ','.join(active),
            'enabled': str(node.activation.enabled),
            'qp_conflict': stats.qp_conflict,
            # the process's scheduling as it is, and why a request was refused (realtime.py)
            'scheduling': scheduling_text(),
            'scheduling_refused': node.scheduling_refused,
        }
        st.values = [KeyValue(key=k, value=v) for k, v in values.items()]
        arr = DiagnosticArray()
        arr.header.stamp = stamp
        arr.status = [st]
        self.publisher.publish(arr)

    def diagnose_failure(self) -> None:
        """Name the constraints that conflict (a few ms, once per failing spell)."""
        node = self.node
        try:
            node.stats.qp_conflict = diagnose(node.controller).text()
        except Exception as exc:  # noqa: BLE001 - the diagnosis must not make things worse
            node.stats.qp_conflict = f'diagnosis failed: {type(exc).__name__}: {exc}'
        node.say('warning', 'diagnosis', f'QP failure diagnosis: {node.stats.qp_conflict}')


def _budget_text(controller) -> str:
    budget, cap = controller.get_solver_budget()
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
