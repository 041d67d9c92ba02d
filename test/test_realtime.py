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
The controller process's real-time scheduling (orca_ros/ros/realtime.py).

Each case runs in a child process: the test runner's own scheduling is never touched.
"""

import json
import os
import resource
import subprocess
import sys

from orca_ros.ros.realtime import configure_scheduling, scheduling_text
import pytest

CHILD = r"""
import json, os, sys, threading
from orca_ros.ros.realtime import configure_scheduling, process_threads, scheduling_text
priority, cpus = int(sys.argv[1]), json.loads(sys.argv[2])
ev = threading.Event()
before = threading.Thread(target=ev.wait)  # a thread that exists before the request
before.start()
lines = configure_scheduling(priority, cpus)
got = {}
def record():
    tid = threading.get_native_id()
    got['after'] = [os.sched_getscheduler(tid), os.sched_getparam(tid).sched_priority,
                    sorted(os.sched_getaffinity(tid))]
after = threading.Thread(target=record)  # started later: inherits from its creator
after.start(); after.join()
threads = {t: [os.sched_getscheduler(t), os.sched_getparam(t).sched_priority,
               sorted(os.sched_getaffinity(t))] for t in process_threads()}
ev.set(); before.join()
print(json.dumps({'lines': lines, 'threads': threads, 'after': got['after'],
                  'text': scheduling_text()}))
"""


def child(priority, cpus, preexec=None):
    out = subprocess.run(
        [sys.executable, '-c', CHILD, str(priority), json.dumps(cpus)],
        capture_output=True, text=True, timeout=60, preexec_fn=preexec, check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_fifo_and_affinity_reach_every_thread_and_the_threads_started_later():
    cpu = max(os.sched_getaffinity(0))
    r = child(50, [cpu])
    if any(level == 'warning' for level, _ in r['lines']):
        lines = r['lines']
        pytest.skip(f'this machine refuses SCHED_FIFO: {lines}')
    assert len(r['threads']) >= 2  # the main thread and the one started before
    for tid, sched in r['threads'].items():
        assert sched == [os.SCHED_FIFO, 50, [cpu]], tid
    assert r['after'] == [os.SCHED_FIFO, 50, [cpu]]
    n = len(r['threads'])
    assert r['lines'][0] == ['info', f'SCHED_FIFO priority 50 set on {n} thread(s)']
    assert r['lines'][1] == ['info', f'pinned to CPU(s) [{cpu}]']
    want = f'SCHED_FIFO 50, CPUs {cpu}' if os.cpu_count() > 1 else 'SCHED_FIFO 50'
    assert r['text'] == want


def _unprivileged():
    """In the child: no real-time limit, and no CAP_SYS_NICE after exec (root included)."""
    import ctypes  # noqa: PLC0415

    resource.setrlimit(resource.RLIMIT_RTPRIO, (0, 0))
    if os.geteuid() == 0:  # drop it from the bounding set: an exec'd program cannot regain it
        libc = ctypes.CDLL('libc.so.6', use_errno=True)
        assert libc.prctl(24, 23, 0, 0, 0) == 0  # PR_CAPBSET_DROP, CAP_SYS_NICE


def test_a_refused_request_says_why_once_and_leaves_every_thread_at_normal_priority():
    r = child(50, [], preexec=_unprivileged)
    assert len(r['lines']) == 1
    level, text = r['lines'][0]
    assert level == 'warning'
    assert text.startswith('could not set SCHED_FIFO priority 50 (Operation not permitted): '
                           'the control loop runs at normal priority')
    assert 'rtprio' in text and 'thread_priority: 0' in text
    for sched in r['threads'].values():
        assert sched[:2] == [os.SCHED_OTHER, 0]
    assert r['after'][:2] == [os.SCHED_OTHER, 0]
    assert r['text'] == 'normal'


def test_priority_zero_and_an_empty_affinity_leave_the_scheduling_alone():
    r = child(0, [])
    assert r['lines'] == []
    assert {tuple(s[:2]) for s in r['threads'].values()} == {(os.SCHED_OTHER, 0)}


def test_bad_requests_are_named_and_change_nothing():
    before = scheduling_text()
    lines = configure_scheduling(120, [100000])
    assert lines[0] == ('error', 'thread_priority 120 is outside [0, 99]: scheduling left alone')
    assert lines[1][0] == 'error'
    assert lines[1][1].startswith('cpu_affinity [100000]: CPU(s) [100000] not available')
    assert lines[1][1].endswith('running unpinned')
    assert len(lines) == 2 and scheduling_text() == before
