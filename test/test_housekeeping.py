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
"""The node's slow jobs run in the slack after its cycles, one slice per cycle (a fake clock)."""

from orca_ros.ros.housekeeping import Housekeeping


class Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def make(period=1e-3):
    clock, errors, log = Clock(), [], []
    hk = Housekeeping(period, lambda name, exc: errors.append((name, str(exc))), clock)
    return hk, clock, errors, log


def sliced(log, name, n):
    def job():
        for i in range(n):
            log.append((name, i))
            yield
        log.append((name, 'end'))

    job.__name__ = f'_{name}'
    return job


def cycle(hk, clock, period=1e-3):
    clock.t += period
    hk.after_cycle()


def test_in_the_loop_a_due_job_runs_one_slice_per_cycle_after_the_command():
    hk, clock, errors, log = make()
    report = hk.timer_callback(sliced(log, 'report', 3))
    cycle(hk, clock)  # the loop runs
    report()
    assert log == []  # queued, not run in the timer's callback
    report()  # due again before it ran: not queued twice
    for _ in range(4):
        cycle(hk, clock)
    # its first slice in the first cycle after it was due, the end in the fourth
    assert log == [('report', 0), ('report', 1), ('report', 2), ('report', 'end')]
    cycle(hk, clock)
    assert len(log) == 4 and hk.slices_run == 4 and errors == []


def test_jobs_queue_in_order_and_plain_functions_take_one_slice():
    hk, clock, errors, log = make()
    a = hk.timer_callback(sliced(log, 'a', 1))

    def _gc():
        log.append(('gc', 'whole'))

    gc = hk.timer_callback(_gc)
    cycle(hk, clock)
    gc()
    a()
    cycle(hk, clock)
    assert log == [('gc', 'whole')]
    cycle(hk, clock)
    cycle(hk, clock)
    assert log == [('gc', 'whole'), ('a', 0), ('a', 'end')]


def test_out_of_the_loop_a_timer_finishes_the_queue_then_runs_its_job_whole():
    hk, clock, errors, log = make()
    a = hk.timer_callback(sliced(log, 'a', 2))
    b = hk.timer_callback(sliced(log, 'b', 1))
    cycle(hk, clock)
    a()
    cycle(hk, clock)  # a's first slice
    clock.t += 2.5e-3  # no cycle for more than two periods: the loop stopped (stale state)
    assert not hk.in_loop()
    b()
    assert log == [('a', 0), ('a', 1), ('a', 'end'), ('b', 0), ('b', 'end')]
    b()  # and again, at once
    assert log[-2:] == [('b', 0), ('b', 'end')]
    assert errors == []


def test_a_raising_job_is_reported_and_dropped_and_the_others_go_on():
    hk, clock, errors, log = make()

    def _broken():
        log.append(('broken', 0))
        yield
        raise ValueError('bad feedback')

    def _raises_at_once():
        raise RuntimeError('no publisher')

    broken = hk.timer_callback(_broken)
    at_once = hk.timer_callback(_raises_at_once)
    ok = hk.timer_callback(sliced(log, 'ok', 1))
    cycle(hk, clock)
    broken()
    at_once()
    ok()
    for _ in range(5):
        cycle(hk, clock)  # never raises into the cycle
    assert errors == [('broken', 'bad feedback'), ('raises_at_once', 'no publisher')]
    assert log == [('broken', 0), ('ok', 0), ('ok', 'end')]
    # out of the loop too
    clock.t += 1.0
    broken()
    assert errors[-1] == ('broken', 'bad feedback')
