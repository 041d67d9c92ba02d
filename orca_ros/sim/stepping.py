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
"""Stepping a simulated world for a while, at its own pace or the wall clock's (either world)."""

from __future__ import annotations

import time
from typing import Callable


def run_world(world, duration: float | None = None, real_time: bool = False,
              should_stop: Callable[[], bool] | None = None) -> None:
    """
    Step ``world`` until ``duration`` simulated seconds passed or ``should_stop()``.

    Forever if ``duration`` is None; ``real_time``: no faster than the wall clock.
    """
    end = None if duration is None else world.sim_time + duration
    t_wall0, t_sim0 = time.perf_counter(), world.sim_time
    while (end is None or world.sim_time < end - 1e-12) and not (should_stop and should_stop()):
        world.step()
        if real_time:
            ahead = (world.sim_time - t_sim0) - (time.perf_counter() - t_wall0)
            if ahead > 0:
                time.sleep(ahead)
