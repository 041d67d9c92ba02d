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
A thread's CPU time and run-queue wait from Linux's /proc (schedstat).

What a shared machine lets one claim about a periodic loop: its own work per cycle (CPU time
spent by its thread) and the time it waited for a CPU, apart from each other.
"""

from __future__ import annotations

import os


def thread_schedstat(pid: int, tid: int | None = None) -> tuple[float, float] | None:
    """
    Return (CPU time, time waiting on a run queue) [s] of thread ``tid`` of process ``pid``.

    ``tid`` None: the main thread. None when the kernel has no schedstats (or the thread ended).
    """
    path = f'/proc/{pid}/task/{pid if tid is None else tid}/schedstat'
    if not os.path.exists(path):
        return None
    try:
        with open(path) as fh:
            run, wait, _ = fh.read().split()
    except OSError:
        return None
    return int(run) * 1e-9, int(wait) * 1e-9
