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
Fixed-size window of the latest samples of a scalar signal (loop periods, solve times...).

A node running for hours at 1 kHz must not grow: the window is one preallocated array written in a
circle, so pushing a sample allocates nothing; statistics (quantiles, mean, max) are computed on
demand, off the hot path (e.g. by a diagnostics timer), over the samples currently held.
"""

from __future__ import annotations

import numpy as np


class RingBuffer:
    def __init__(self, capacity: int):
        capacity = int(capacity)
        if capacity < 1:
            raise ValueError(f'ring buffer capacity must be >= 1, got {capacity}')
        self._data = np.zeros(capacity)
        self._next = 0
        self._count = 0
        self.total = 0  # samples pushed since creation (or the last clear)

    @property
    def capacity(self) -> int:
        return self._data.shape[0]

    def __len__(self) -> int:
        return self._count

    def push(self, value: float) -> None:
        i = self._next
        self._data[i] = value
        i += 1
        self._next = 0 if i == self._data.shape[0] else i
        if self._count < self._data.shape[0]:
            self._count += 1
        self.total += 1

    def clear(self) -> None:
        self._next = self._count = self.total = 0

    def values(self) -> np.ndarray:
        """Return the samples held, oldest first (a copy)."""
        n, cap = self._count, self._data.shape[0]
        if n < cap:
            return self._data[:n].copy()
        return np.concatenate((self._data[self._next:], self._data[: self._next]))

    def quantile(self, q: float, default: float = 0.0) -> float:
        """Return the q-th quantile, q in 0..1, of the samples held; ``default`` when empty."""
        if self._count == 0:
            return default
        return float(np.quantile(self._data[: self._count], q))

    def quantiles(self, qs, default: float = 0.0) -> list[float]:
        """Return the quantiles ``qs`` (each in 0..1) of the samples held, in one partition."""
        if self._count == 0:
            return [default] * len(qs)
        return [float(v) for v in np.quantile(self._data[: self._count], qs)]

    def mean(self, default: float = 0.0) -> float:
        return float(self._data[: self._count].mean()) if self._count else default

    def max(self, default: float = 0.0) -> float:  # noqa: A003 (ORCA API name)
        return float(self._data[: self._count].max()) if self._count else default

    def latest(self, k: int) -> np.ndarray:
        """Return the last ``k`` samples (fewer if fewer are held), oldest first (a copy)."""
        k = max(0, min(int(k), self._count))
        if k == 0:
            return np.zeros(0)
        i, cap = self._next, self._data.shape[0]
        if k <= i:
            return self._data[i - k: i].copy()
        return np.concatenate((self._data[cap - (k - i):], self._data[:i]))
