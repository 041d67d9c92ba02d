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
"""The discrete-time viable bound (ViableBound) against its definition, on random states."""

import numpy as np

from orca_ros.constraint.viable_bound import ViableBound


def test_viable_states_stay_viable_and_never_need_more_than_a():
    rng = np.random.default_rng(3)
    n = 20000
    dt = 1e-3
    acc = rng.uniform(0.5, 20.0, n)
    room = rng.uniform(0.0, 0.5, n)
    # velocities up to the viability limit v^2 <= 2 A room, and away from the limit
    v = rng.uniform(-1.0, 1.0, n) * np.sqrt(2.0 * acc * room)
    vb = ViableBound(n)
    vb.set_acceleration(acc)
    out = np.zeros(n)
    vb.upper(room, v, dt, 0.05, out)
    assert np.all(out >= -acc - 1e-9)  # braking at A is always admissible
    # at the bound itself: the next position is within the limit, the next state can stop at A
    v1 = v + dt * out
    room1 = room - dt * v - 0.5 * dt * dt * out
    assert np.all(room1 >= -1e-12)
    moving = v1 > 0.0
    assert np.all(v1[moving] ** 2 <= 2.0 * acc[moving] * room1[moving] * (1 + 1e-9) + 1e-12)


def test_states_past_viability_brake_and_infinite_limits_are_free():
    dt = 1e-3
    vb = ViableBound(3)
    vb.set_acceleration(5.0)
    out = np.zeros(3)
    # fast towards a close limit: brake at A at least (the next position is the binding bound)
    vb.upper(np.array([0.01, 1e-4, np.inf]), np.array([2.0, 0.05, 3.0]), dt, 0.05, out)
    assert out[0] <= -5.0
    assert 1e-4 - dt * 0.05 - 0.5 * dt * dt * out[1] >= -1e-15
    assert out[2] == np.inf
