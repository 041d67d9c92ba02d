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
The PID's kernel (numba): :meth:`.pid_controller.PIDController.compute_command` on a record.

The compiled cycle keeps each servoed task's gains, windup limits and integral in one float
record (:meth:`.PIDController.keep_in`); this kernel computes the PID's command from there,
formula for formula as the reference method.
"""

from __future__ import annotations

from ..utils.jit import njit


@njit
def pid_command(rec, kp, ki, kd, windup, integral, err, derr, n, dt, out):
    """Write P e + D e_dot (+ I integral, clamped) into out, as PIDController.compute_command."""
    any_i = False
    for i in range(n):
        if rec[ki + i] != 0.0:
            any_i = True
    for i in range(n):
        out[i] = rec[kp + i] * err[i] + rec[kd + i] * derr[i]
    if dt > 0.0 and any_i:
        for i in range(n):
            rec[integral + i] += err[i] * dt
            gi = rec[ki + i]
            term = gi * rec[integral + i]
            w = rec[windup + i]
            term = min(w, max(-w, term))
            if gi != 0.0:
                rec[integral + i] = term / gi
            out[i] += term
