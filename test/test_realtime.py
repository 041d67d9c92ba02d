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

Each case runs in a child process: the test runner's own scheduling is never touched. Threads come
and go in a process (a joined thread's kernel task outlives its join by a moment): a thread listed
may be gone when it is set or read, which the node skips and so does the child; a child that fails
all the same fails its test at once, with its stderr.
"""

import json
import os
import re
import resource
import subprocess
import sys

from orca_ros.ros.realtime import configure_scheduling, scheduling_text
import pytest

READ = r"""
import json, os, sys, threading
from orca_ros.ros import realtime

def read(tid):
    # [policy, priority, CPUs] of a thread; None: it ended since it was listed
    try:
        return [os.sched_getscheduler(tid), os.sched_getparam(tid).sched_priority,
                sorted(os.sched_getaffinity(tid))]
    except ProcessLookupError:
        return None

def settings():
    # the process's threads that are still there when read
    return {t: s for t in realtime.process_threads() if (s := read(t)) is not None}
"""

CHILD = READ + r"""
priority, cpus = int(sys.argv[1]), json.loads(sys.argv[2])
ev = threading.Event()
before = threading.Thread(target=ev.wait, daemon=True)  # a thread that exists before the request
before.start()
try:
    listed = realtime.process_threads()
    lines = realtime.configure_scheduling(priority, cpus)
    got = {}
    def record():
        got['after'] = read(threading.get_native_id())
    after = threading.Thread(target=record)  # started later: inherits from its creator
    after.start(); after.join()
    threads = settings()
finally:
    ev.set()
before.join()
print(json.dumps({'lines': lines, 'threads': threads, 'after': got['after'],
                  'listed': listed, 'text': realtime.scheduling_text()}))
"""

CHURN = READ + r"""
priority, cpus, rounds = int(sys.argv[1]), json.loads(sys.argv[2]), int(sys.argv[3])
stop, churning = threading.Event(), threading.Event()
waiters = [threading.Thread(target=stop.wait, daemon=True) for _ in range(2)]
born = [0]
def churn():  # short-lived threads, one after another, until the rounds are done
    while not stop.is_set():
        t = threading.Thread(target=int)
        t.start(); t.join()
        born[0] += 1
        churning.set()
churner = threading.Thread(target=churn, daemon=True)
try:
    for t in waiters + [churner]:
        t.start()
    churning.wait()
    # and one thread certainly gone, in every listing below: the race, made certain
    gone = threading.Thread(target=int)
    gone.start(); gone.join()
    for _ in range(10**6):  # (its kernel task outlives the join by a moment)
        if not os.path.exists(f'/proc/self/task/{gone.native_id}'):
            break
        os.sched_yield()
    else:
        sys.exit(f'thread {gone.native_id} still listed')
    listing = realtime.process_threads
    realtime.process_threads = lambda: sorted(listing() + [gone.native_id])
    missed = {'gone': 0, 'others': 0}  # the setters' ProcessLookupError, by thread
    def counted(setter):
        def wrapped(tid, *args):
            try:
                return setter(tid, *args)
            except ProcessLookupError:
                missed['gone' if tid == gone.native_id else 'others'] += 1
                raise
        return wrapped
    os.sched_setscheduler = counted(os.sched_setscheduler)
    os.sched_setaffinity = counted(os.sched_setaffinity)
    unread = 0  # threads listed, gone when read
    for _ in range(rounds):
        lines = realtime.configure_scheduling(priority, cpus)
        unread += sum(read(t) is None for t in realtime.process_threads())
    ids = [threading.main_thread().native_id] + [t.native_id for t in waiters + [churner]]
    long_lived = [read(t) for t in ids]
finally:
    stop.set()
churner.join()
print(json.dumps({'lines': lines, 'long_lived': long_lived, 'missed': missed, 'unread': unread,
                  'born': born[0]}))
"""


def child(priority, cpus, preexec=None, script=CHILD, args=()):
    """Run ``script`` in a child process; return its last line, read as JSON."""
    argv = [sys.executable, '-c', script, str(priority), json.dumps(cpus), *map(str, args)]
    try:
        out = subprocess.run(argv, capture_output=True, text=True, timeout=60, preexec_fn=preexec)
    except subprocess.TimeoutExpired as exc:  # (a backstop: the child's threads are daemons)
        err = exc.stderr.decode() if isinstance(exc.stderr, bytes) else exc.stderr
        pytest.fail(f'the child did not end in 60 s; its stderr:\n{err}')
    assert out.returncode == 0, f'the child failed ({out.returncode}); its stderr:\n{out.stderr}'
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
    level, text = r['lines'][0]
    set_on = re.fullmatch(r'SCHED_FIFO priority 50 set on (\d+) thread\(s\)', text)
    assert level == 'info' and set_on, r['lines']
    # the threads listed before the request, but those that ended since (not counted)
    kept = set(r['listed']) & {int(t) for t in r['threads']}
    assert len(kept) <= int(set_on.group(1)) <= len(r['listed'])
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


@pytest.mark.parametrize('kind', ['affinity', 'fifo', 'refused'])
def test_threads_that_end_while_the_scheduling_is_set_are_skipped(kind):
    """
    Set the scheduling ROUNDS times over, and list and read it, while threads start and end.

    One thread churns short-lived ones, started and joined without pause; and one thread ended
    before the first request is put in every listing (the race, certain in every call). No call
    fails, each skips the thread gone, and the long-lived threads (the main one, two waiting,
    the churning one) have what was asked: a CPU (at normal priority), SCHED_FIFO 50, or, refused,
    nothing (all threads put back).
    """
    rounds = 200
    mine = sorted(os.sched_getaffinity(0))
    cpu = max(mine)
    priority, cpus, preexec = {'affinity': (0, [cpu], None), 'fifo': (50, [], None),
                               'refused': (50, [], _unprivileged)}[kind]
    r = child(priority, cpus, preexec, CHURN, (rounds,))
    print(f"{kind}: {r['born']} threads started and ended over {rounds} requests; threads gone "
          f"when set, but the one added: {r['missed']['others']}; when read: "
          f"{r['unread'] - rounds}")
    assert r['born'] > 0
    assert r['missed']['gone'] == rounds  # each call met the thread gone, and went on
    assert r['unread'] >= rounds
    refused = [text for level, text in r['lines'] if level == 'warning']
    if kind == 'affinity':
        assert r['lines'] == [['info', f'pinned to CPU(s) [{cpu}]']]
        want = [os.SCHED_OTHER, 0, [cpu]]
    elif kind == 'fifo' and not refused:
        level, text = r['lines'][0]
        set_on = re.fullmatch(r'SCHED_FIFO priority 50 set on (\d+) thread\(s\)', text)
        assert len(r['lines']) == 1 and level == 'info' and set_on, r['lines']
        assert int(set_on.group(1)) >= 4  # (the gone one not counted)
        want = [os.SCHED_FIFO, 50, mine]
    else:  # refused (or this machine refuses)
        assert len(r['lines']) == 1 and len(refused) == 1, r['lines']
        assert refused[0].startswith('could not set SCHED_FIFO priority 50')
        want = [os.SCHED_OTHER, 0, mine]
    assert r['long_lived'] == [want] * 4


def test_bad_requests_are_named_and_change_nothing():
    before = scheduling_text()
    lines = configure_scheduling(120, [100000])
    assert lines[0] == ('error', 'thread_priority 120 is outside [0, 99]: scheduling left alone')
    assert lines[1][0] == 'error'
    assert lines[1][1].startswith('cpu_affinity [100000]: CPU(s) [100000] not available')
    assert lines[1][1].endswith('running unpinned')
    assert len(lines) == 2 and scheduling_text() == before
