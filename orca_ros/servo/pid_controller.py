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
"""Vector PID controller with per-axis gains and anti-windup clamp on the integral term."""

from __future__ import annotations

import numpy as np

from ..common.watched import keep_in


def _as_gain(value, dim: int, what: str) -> np.ndarray:
    g = np.asarray(value, dtype=float).reshape(-1)
    if g.size == 1:
        g = np.full(dim, float(g[0]))
    if g.shape != (dim,):
        raise ValueError(f'{what}: expected a scalar or {dim} values, got {g.size}')
    if not np.all(np.isfinite(g)):
        raise ValueError(f'{what}: gains must be finite, got {g}')
    return g


class PIDController:
    """U = P e + I integral(e) + D e_dot, each gain a vector (one value per axis)."""

    def __init__(self, dimension: int):
        self.dimension = int(dimension)
        self._p = np.zeros(self.dimension)
        self._i = np.zeros(self.dimension)
        self._d = np.zeros(self.dimension)
        self._windup = np.full(self.dimension, np.inf)
        self._integral = np.zeros(self.dimension)
        self._out = np.zeros(self.dimension)

    def resize(self, dimension: int) -> None:
        self.__init__(dimension)

    def set_proportional_gain(self, gain) -> None:
        self._p[:] = _as_gain(gain, self.dimension, 'proportional gain')  # in place: views

    def set_integral_gain(self, gain) -> None:
        self._i[:] = _as_gain(gain, self.dimension, 'integral gain')

    def set_derivative_gain(self, gain) -> None:
        self._d[:] = _as_gain(gain, self.dimension, 'derivative gain')

    def set_windup_limit(self, limit) -> None:
        """Bound on |I * integral(e)| per axis (the integral term's contribution)."""
        lim = _as_gain(limit, self.dimension, 'windup limit')
        if np.any(lim < 0):
            raise ValueError('windup limit must be >= 0')
        self._windup[:] = lim

    def get_proportional_gain(self) -> np.ndarray:
        return self._p.copy()

    def get_integral_gain(self) -> np.ndarray:
        return self._i.copy()

    def get_derivative_gain(self) -> np.ndarray:
        return self._d.copy()

    def get_windup_limit(self) -> np.ndarray:
        return self._windup.copy()

    def keep_in(self, record: np.ndarray, starts) -> None:
        """
        Keep P, I, D, the windup limits and the integral in ``record``, at ``starts`` (that order).

        Each becomes a view on its ``dimension`` values of the record (the compiled cycle's
        kernel, :func:`.pid_kernel.pid_command`, computes this PID there); the setters write in
        place.
        """
        keep_in(self, record, dict(zip(('p', 'i', 'd', 'windup', 'integral'), starts)))

    def reset(self) -> None:
        self._integral[:] = 0.0

    def compute_command(
        self, error: np.ndarray, derivative_error: np.ndarray, dt: float
    ) -> np.ndarray:
        """Command for this cycle; the returned array is reused at the next call."""
        out = self._out
        np.multiply(self._p, error, out=out)
        out += self._d * derivative_error
        if dt > 0.0 and self._i.any():
            self._integral += error * dt
            term = self._i * self._integral
            np.clip(term, -self._windup, self._windup, out=term)
            # keep the stored integral consistent with the clamped contribution
            nz = self._i != 0.0
            self._integral[nz] = term[nz] / self._i[nz]
            out += term
        return out
