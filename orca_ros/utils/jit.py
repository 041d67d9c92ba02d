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
numba's ``njit`` as the compiled cycle uses it: cached on disk, no Python objects, no GIL.

The cache goes next to the package's sources (``__pycache__``) where they are writable; where the
package is installed read-only (a ROS install under /opt), numba falls back to a user-writable
folder (its user-wide cache locator, under ``$XDG_CACHE_HOME`` or ``~/.cache``), and
``NUMBA_CACHE_DIR`` names one explicitly. Without numba, importing this raises MissingDependency
with the pip line (the controller then runs its reference path and says so).
"""

from __future__ import annotations

from .optional_import import optional_import

numba = optional_import('numba', 'the compiled control cycle', 'or compiled: false')


def njit(fn):
    """Compile ``fn`` in nopython mode, cached on disk."""
    return numba.njit(cache=True, nogil=True, error_model='numpy')(fn)
