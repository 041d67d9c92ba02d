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
A node's periodic jobs that are not control (feedback, diagnostics, garbage collection).

Why: the control cycle and these jobs share one executor thread. A job that runs when its own
timer fires may hold the thread when the control timer is due, and that cycle is late by the
job's length: in the 1 kHz node a diagnostics report takes longer than a period, the feedback
and a young-generation collection a sizeable part of one, and they made most of the late
control periods (docs/benchmarks.md).

How: a job is a generator function; each ``yield`` marks where it may pause. While the control
loop runs (a cycle ended less than two periods ago), a job's timer only queues it, and each cycle,
once its command is out, runs one slice of the queued jobs: the slices fill the slack of the
period instead of delaying the next cycle. When the loop does not run (no state yet, a paused
simulator), the timer runs the whole job at once, as before.
"""

from __future__ import annotations

from collections import deque
import gc
import time


class Housekeeping:
    """
    Queue of a node's slow periodic jobs, run in slices after its control cycles.

    ``period``: the control period [s]; ``on_error(name, exc)``: told of a job that raised (the
    job is dropped, the cycle goes on); ``clock``: monotonic seconds.
    """

    def __init__(self, period: float, on_error, clock=time.monotonic):
        self.period = float(period)
        self.on_error = on_error
        self._clock = clock
        self._last_cycle = float('-inf')
        self._queue: deque = deque()
        self._current = None  # (name, generator) of the job being run
        self.slices_run = 0

    def in_loop(self) -> bool:
        """Whether the control loop runs (a cycle ended less than two periods ago)."""
        return self._clock() - self._last_cycle < 2.0 * self.period

    def timer_callback(self, job):
        """
        Make the timer callback of ``job``.

        ``job``: a function without arguments, run in one slice, or a generator function, run in
        as many slices as it yields plus one.

        In the loop: queue the job (once: a job queued or in progress is not queued again). Out
        of it: finish what is queued, then run the job whole.
        """
        name = getattr(job, '__name__', 'job').lstrip('_')

        def due() -> None:
            pending = [n for n, _ in self._queue]
            if self._current is not None:
                pending.append(self._current[0])
            if name not in pending:
                self._queue.append((name, job))
            if not self.in_loop():
                self.drain()

        due.__name__ = name
        return due

    def after_cycle(self) -> None:
        """Call once a cycle's command is out: run one slice of the queued jobs."""
        self._last_cycle = self._clock()
        if self._current is None:
            if not self._queue:
                return
            self.slices_run += 1
            self._current = self._start(*self._queue.popleft())  # a plain function runs here
            if self._current is None:
                return
        else:
            self.slices_run += 1
        if not self._step(*self._current):
            self._current = None

    def drain(self) -> None:
        """Finish the job in progress and every queued one."""
        while self._current is not None or self._queue:
            if self._current is None:
                self._current = self._start(*self._queue.popleft())
            while self._current is not None and self._step(*self._current):
                pass
            self._current = None

    def _start(self, name: str, job):
        """Call ``job``: (name, its slices) to run on, or None when it ran whole or raised."""
        try:
            slices = job()
        except Exception as exc:  # noqa: BLE001 - a job must not touch the control cycle
            self.on_error(name, exc)
            return None
        return (name, slices) if hasattr(slices, '__next__') else None

    def _step(self, name: str, slices) -> bool:
        """Run one slice of a job; False when the job has ended (or raised)."""
        try:
            next(slices)
            return True
        except StopIteration:
            return False
        except Exception as exc:  # noqa: BLE001
            self.on_error(name, exc)
            return False


class GarbageCollection:
    """
    Garbage collection kept out of the control cycle (``manage_gc``).

    At the first valid state, before the first command, :meth:`freeze` collects everything,
    freezes what is alive out of the collector's sight and stops automatic collection: the full
    collection pauses a process for tens of milliseconds, and a command stream that pauses right
    after it started lets a robot the simulator or its drives just handed over sag. Then
    :meth:`collect_garbage`, a low-rate job between cycles, collects the young generations (the
    cycle itself allocates little and makes no reference cycles). ``managed`` False: Python's
    own collection, untouched.
    """

    def __init__(self, managed: bool):
        self.managed = managed
        self.frozen = False

    @property
    def due(self) -> bool:
        """Say whether :meth:`freeze` is still to run (managed, not frozen yet)."""
        return self.managed and not self.frozen

    def freeze(self) -> None:
        """Collect everything, freeze what is alive, stop automatic collection (once)."""
        gc.collect()
        gc.freeze()
        gc.disable()
        self.frozen = True

    def collect_garbage(self) -> None:
        """Between cycles, once frozen: collect the young generations."""
        if self.frozen:
            gc.collect(1)
