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
The controller process's scheduling: real-time priority and CPU affinity (Linux).

As ros2_control's controller manager does, the node asks for ``SCHED_FIFO`` at
``thread_priority`` (50 by default; 0 leaves the scheduling alone) and, when ``cpu_affinity``
lists CPUs, pins itself to them. Every thread of the process at that moment is set (the executor's,
the middleware's), and threads started later inherit it from their creator. A thread that ends
between the listing and its setting is skipped: threads come and go while the node runs.

Why (bench/bench_node_soak.py; the figures in docs/benchmarks.md): at normal priority the
control timer's wake-up waited behind the simulator and the middleware's threads, and a cycle
could be preempted half-way; at ``SCHED_FIFO`` the period's 99th percentile stays close to the
nominal period.

Where the system refuses (no ``CAP_SYS_NICE``, no ``rtprio`` limit, a container), the node says
so in one warning and runs at normal priority: nothing else changes. A CPU that is not available
to the process is an error in the log, and the node runs unpinned.
"""

from __future__ import annotations

import os

SCHED_HELP = (
    'to allow it, give the user a real-time limit (/etc/security/limits.conf: '
    "'<user> - rtprio 99') or CAP_SYS_NICE; thread_priority: 0 turns this request off"
)


def process_threads() -> list[int]:
    """Return the ids of this process's threads (Linux: /proc/self/task)."""
    try:
        return sorted(int(t) for t in os.listdir('/proc/self/task'))
    except OSError:
        return [0]  # the calling thread only


def configure_scheduling(priority: int, cpus) -> list[tuple[str, str]]:
    """
    Set ``SCHED_FIFO`` at ``priority`` and the affinity ``cpus`` on every thread of this process.

    ``priority`` 1..99, 0: unchanged; ``cpus`` empty: unchanged. Returns the log lines to write,
    as ``(level, text)``: what was set, or why not. A thread listed that has ended by the time it
    is set is skipped (:func:`_each`), and not counted among those set.
    """
    out: list[tuple[str, str]] = []
    priority = int(priority)
    cpus = sorted({int(c) for c in cpus or ()})
    if not 0 <= priority <= 99:
        out.append(
            ('error', f'thread_priority {priority} is outside [0, 99]: scheduling left alone')
        )
        priority = 0
    threads = process_threads()
    if priority > 0:
        if not hasattr(os, 'sched_setscheduler'):
            out.append(('warning', 'SCHED_FIFO is not available on this platform'))
        else:
            try:
                fifo = os.sched_param(priority)
                n = sum(_each(os.sched_setscheduler, tid, os.SCHED_FIFO, fifo) for tid in threads)
                out.append(('info', f'SCHED_FIFO priority {priority} set on {n} thread(s)'))
            except OSError as exc:
                for tid in threads:  # all or none: a half-set process is worse than neither
                    try:
                        os.sched_setscheduler(tid, os.SCHED_OTHER, os.sched_param(0))
                    except OSError:  # (ended since, too)
                        pass
                out.append(
                    (
                        'warning',
                        f'could not set SCHED_FIFO priority {priority} '
                        f'({exc.strerror or exc}): the control loop runs at normal priority; '
                        f'{SCHED_HELP}',
                    )
                )
    if cpus:
        allowed = sorted(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else []
        missing = [c for c in cpus if c not in allowed]
        if missing:
            out.append(
                (
                    'error',
                    f'cpu_affinity {cpus}: CPU(s) {missing} not available to this process '
                    f'(available: {allowed}): running unpinned',
                )
            )
        else:
            for tid in threads:
                _each(os.sched_setaffinity, tid, cpus)
            out.append(('info', f'pinned to CPU(s) {cpus}'))
    return out


def _each(setter, tid: int, *args) -> bool:
    """
    Apply ``setter`` to thread ``tid``; return whether it was there to set.

    A thread that ended since it was listed is skipped (the kernel no longer knows its id:
    ``ProcessLookupError``); any other refusal is raised.
    """
    try:
        setter(tid, *args)
    except ProcessLookupError:
        return False
    return True


def scheduling_text(tid: int = 0) -> str:
    """Describe a thread's scheduling as it is (0: the calling one): ``SCHED_FIFO 50, CPUs 1``."""
    try:
        policy = os.sched_getscheduler(tid)
        prio = os.sched_getparam(tid).sched_priority
        cpus = sorted(os.sched_getaffinity(tid))
    except (AttributeError, OSError):
        return 'unknown'
    name = {os.SCHED_FIFO: 'SCHED_FIFO', os.SCHED_RR: 'SCHED_RR'}.get(policy)
    text = f'{name} {prio}' if name else 'normal'
    if len(cpus) < os.cpu_count():
        text += f", CPUs {','.join(map(str, cpus))}"
    return text
