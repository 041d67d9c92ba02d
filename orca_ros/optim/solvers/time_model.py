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
A solver's time model: how long its next solve may take, and so how many iterations fit.

t = fixed + (iterations - 1) * per, two running estimates kept in ``model = [fixed, per]``
(seconds). They follow a rise quickly and a fall slowly: a harder problem shrinks the cap at
once, and a sample far above them (a preempted solve) moves them at most to 1.6x.

Plain functions of numbers and a two-value array, calling nothing: the back-ends call them in
Python (:class:`.base.QPBackend`), the compiled cycle compiles the same functions into its
kernel (:mod:`orca_ros.optim.compiled.cycle_kernel`), so both budget a solve alike.
"""

from __future__ import annotations

import math

#: share of the time left that the iteration cap is computed for: the cost of an iteration
#: varies with the problem (a failing solve's iterations cost a few times a warm feasible one's,
#: with ProxQP), so the model's estimate may be low by that much on the first hard cycle without
#: the cycle overrunning its budget
TIME_SHARE = 0.4


def iteration_cap(model, left: float, cap: int, least: int) -> int:
    """
    Return the iterations that fit in ``left`` seconds: min(cap, max(least, 1 + n)).

    n: the further iterations after the first that fit in TIME_SHARE of the time left.
    ``left`` inf (no deadline) or an empty model: ``cap``.
    """
    fixed = model[0]
    if fixed <= 0.0 or math.isinf(left):
        return cap
    per = model[1] if model[1] > 0.0 else fixed
    n = (TIME_SHARE * left - fixed) / per
    if n < least - 1:
        return least
    return 1 + int(n) if n < cap else cap  # (n may be inf: a model of ~0 s)


def record(model, seconds: float, iterations: int) -> None:
    """
    Update ``model`` with one solve of ``iterations`` that took ``seconds``.

    One or two iterations (or no estimate yet) update ``fixed``, more update ``per``.
    """
    k, sample = 0, seconds if iterations <= 2 else seconds / iterations
    if iterations > 2 and model[0] != 0.0:
        extra = seconds - model[0]
        k, sample = 1, (extra if extra > 0.0 else 0.0) / (iterations - 1)
    estimate = model[k]
    if estimate == 0.0:
        model[k] = sample
    elif sample > estimate:  # a sample above: followed at once, at most to 1.6x
        model[k] = 0.7 * estimate + 0.3 * min(sample, 3.0 * estimate)
    else:
        model[k] = 0.95 * estimate + 0.05 * sample
