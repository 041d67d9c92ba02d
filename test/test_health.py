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
"""What /diagnostics says, decided from the controller's counters (no ROS needed)."""

import numpy as np
from orca_ros.ros.health import assess, ERROR, OK, TaskErrorWatch, WARN
from orca_ros.utils.ring_buffer import RingBuffer
from orca_ros.utils.throttled_log import ThrottledLog

P = 1e-3


def judge(**kw):
    args = {
        'have_state': True,
        'state_age': 0.0,
        'state_timeout': 0.05,
        'safe_reason': None,
        'safe_cause': None,
        'qp_failures': 0,
        'dropped_levels': 0,
        'periods': np.full(200, P),
        'nominal_period': P,
        'check_periods': True,
        'overrun_factor': 1.5,
        'persistent_errors': [],
    }
    args.update(kw)
    return assess(**args)


def test_healthy_is_ok():
    assert judge() == (OK, 'controlling')


def test_each_fault_has_its_level_and_reason():
    assert judge(have_state=False) == (WARN, 'waiting for joint_states')
    lvl, msg = judge(
        safe_reason='no QP solution (primal_infeasible)', safe_cause='safe:qp', qp_failures=40
    )
    assert (
        lvl == ERROR and msg == 'safe command: no QP solution (primal_infeasible)'
    )  # counted once, not twice
    lvl, msg = judge(
        qp_failures=3
    )  # failed and recovered since the last report: still an error to report
    assert lvl == ERROR and '3 QP failure(s)' in msg
    # and what the last failure was
    lvl, msg = judge(qp_failures=3, last_failure='no QP solution (primal_infeasible)')
    assert (lvl, msg) == (
        ERROR, '3 QP failure(s) since the last report (last: no QP solution (primal_infeasible))')
    lvl, msg = judge(state_age=0.3)
    assert lvl == ERROR and 'stale' in msg
    lvl, msg = judge(dropped_levels=2)
    assert lvl == WARN and 'dropped a priority level' in msg
    slow = np.full(200, P)
    slow[::10] = 4 * P  # 10 % of the periods at 4 ms
    lvl, msg = judge(periods=slow)
    assert lvl == WARN and 'loop overruns: 20 of 200' in msg
    assert judge(periods=slow, check_periods=False) == (
        OK,
        'controlling',
    )  # lockstep: the simulator's pace
    # a starved loop: 4 cycles in a 0.2 s report at a 1 ms period (too few to judge periods)
    lvl, msg = judge(periods=np.full(4, 0.05), interval=0.2)
    assert lvl == WARN and msg.startswith('loop overruns: 4 cycles in 200 ms (200 expected')
    assert judge(interval=0.2) == (OK, 'controlling')  # 200 cycles in 0.2 s: on time
    lvl, msg = judge(persistent_errors=[('ee', 0.12, 2.5)])
    assert lvl == WARN and "task 'ee' error 0.12 for 2.5 s" in msg


def test_deliberate_hold_is_not_an_error():
    lvl, msg = judge(
        safe_reason='controller disabled (~/enable false)', safe_cause='safe:disabled'
    )
    assert lvl == OK and msg.startswith('holding: controller disabled')
    lvl, msg = judge(
        safe_reason='controller disabled (~/enable false)',
        safe_cause='safe:disabled',
        dropped_levels=1,
    )
    assert lvl == WARN and 'holding' in msg


def test_error_watch_needs_persistence():
    w = TaskErrorWatch(0.01, 2.0)
    for k in range(100):
        w.observe('ee', 0.05, k * 0.02)  # 2 s above the threshold ...
    assert w.persistent(1.99) == []
    w.observe('ee', 0.05, 2.1)
    assert [n for n, _, _ in w.persistent(2.1)] == ['ee']
    w.observe('ee', 0.001, 2.2)  # ... reached: cleared at once
    assert w.persistent(5.0) == []


def test_ring_buffer_latest():
    rb = RingBuffer(5)
    for x in range(8):
        rb.push(float(x))
    np.testing.assert_array_equal(rb.latest(3), [5.0, 6.0, 7.0])
    np.testing.assert_array_equal(rb.latest(10), [3.0, 4.0, 5.0, 6.0, 7.0])
    assert rb.latest(0).size == 0


def test_ring_buffer_quantiles_in_one_call_equal_them_one_by_one():
    rng = np.random.default_rng(3)
    rb = RingBuffer(1000)
    assert rb.quantiles((0.5, 0.99), default=-1.0) == [-1.0, -1.0]
    for x in rng.exponential(1e-3, 1500):  # wrapped round once
        rb.push(float(x))
    qs = (0.5, 0.99, 0.999)
    assert rb.quantiles(qs) == [rb.quantile(q) for q in qs]


class _Log:
    def __init__(self):
        self.lines = []

    def error(self, text):
        self.lines.append(('error', text))

    def info(self, text):
        self.lines.append(('info', text))

    def warning(self, text):
        self.lines.append(('warning', text))


def test_throttled_log_says_when_a_cause_is_due_without_counting():
    """due() answers whether a line would print now; asking holds nothing back, counts nothing."""
    now = [0.0]
    log = _Log()
    say = ThrottledLog(log, period=1.0, clock=lambda: now[0])
    assert say.due('a')
    say('warning', 'a', 'first')
    now[0] = 0.5
    assert not say.due('a') and say.due('b')
    now[0] = 1.0
    assert say.due('a')
    say('warning', 'a', 'second')
    assert log.lines[-1] == ('warning', 'second')  # no 'more like it': due() counted nothing


def test_throttled_log_one_line_per_cause_per_period():
    now = [0.0]
    log = _Log()
    say = ThrottledLog(log, period=1.0, clock=lambda: now[0])
    for k in range(1000):  # 1 kHz of the same fault for 1 s, interleaved with another cause
        now[0] = k * 1e-3
        say('error', 'a', 'fault a')
        if k % 100 == 0:
            say('info', 'b', 'fault b')
    assert log.lines == [('error', 'fault a'), ('info', 'fault b')]
    now[0] = 1.5
    say('error', 'a', 'fault a')
    assert log.lines[-1] == ('error', 'fault a (and 999 more like it since the last report)')
