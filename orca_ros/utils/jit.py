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
package is installed read-only (a ROS install under /opt), to a user-writable folder (numba's
user-wide cache, under ``$XDG_CACHE_HOME`` or ``~/.cache``); ``NUMBA_CACHE_DIR`` names one
explicitly. numba judges a cached kernel by its own source file only, while the cycle's kernels
call each other across files: here every kernel of the package is stamped with a digest of all
the package's kernel sources, so that a change to any of them recompiles all.

Without numba, importing this raises MissingDependency with the pip line (the controller then
runs its reference path and says so).
"""

from __future__ import annotations

import glob
import hashlib
import os
import pickle

from .optional_import import optional_import

numba = optional_import('numba', 'the compiled control cycle', 'or compiled: false')
caching = optional_import('numba.core.caching', 'the compiled control cycle')

_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_SOURCES = sorted(
    glob.glob(os.path.join(_PACKAGE, 'optim', 'compiled', '*.py'))
    + glob.glob(os.path.join(_PACKAGE, '**', '*_kernel.py'), recursive=True)
    # what the kernels read from other files: constants, structures, the solver's C binding
    + [os.path.join(_PACKAGE, *path.split('/')) for path in (
        'optim/solvers/time_model.py', 'optim/solvers/clock.py', 'optim/solvers/daqp_c.py',
        'optim/solvers/direct_daqp.py', 'common/lowered.py', 'constraint/viable_bound.py',
        'utils/struct_type.py', 'utils/jit.py',
    )]
)


def _digest() -> str:
    h = hashlib.sha256()
    for path in _SOURCES:
        with open(path, 'rb') as fh:
            h.update(fh.read())
    return h.hexdigest()


_STAMP = _digest()


def _ours(py_file: str) -> bool:
    return os.path.abspath(py_file).startswith(_PACKAGE + os.sep)


def _stamped(base):
    class Locator(base):
        def get_source_stamp(self):
            return _STAMP

        @classmethod
        def from_function(cls, py_func, py_file):
            return super().from_function(py_func, py_file) if _ours(py_file) else None

    Locator.__name__ = f'OrcaStamped{base.__name__}'
    return Locator


def _tolerant(load_index):
    """
    Wrap numba's index loading: an index it cannot read back is a stale one, not an error.

    numba unpickles a cache index before it compares its stamp; an index written by another
    version of this package may name a module or class that is gone since (a kernel moved to
    another file), and unpickling it raises. Such an index is out of date whatever its stamp:
    read as empty, the kernel compiles and the index is written anew.
    """
    def _load_index(self):
        try:
            return load_index(self)
        except (ImportError, AttributeError, EOFError, pickle.UnpicklingError):
            return {}

    _load_index.orca_tolerant = True
    _load_index.original = load_index
    return _load_index


if not getattr(caching.CacheImpl, '_orca_stamped', False):
    caching.CacheImpl._locator_classes[0:0] = [
        _stamped(caching.UserProvidedCacheLocator),
        _stamped(caching.InTreeCacheLocator),
        _stamped(caching.UserWideCacheLocator),
    ]
    caching.CacheImpl._orca_stamped = True
if not getattr(caching.IndexDataCacheFile._load_index, 'orca_tolerant', False):
    caching.IndexDataCacheFile._load_index = _tolerant(caching.IndexDataCacheFile._load_index)


def njit(fn):
    """Compile ``fn`` in nopython mode, cached on disk."""
    return numba.njit(cache=True, nogil=True, error_model='numpy')(fn)


def entry(dispatcher, *args):
    """
    Return the compiled function of ``dispatcher`` for the types of ``args``, compiled if needed.

    A dispatcher call resolves its arguments' types every time: a Python-level typeof per StructRef
    argument, the costliest, and a lookup per array. The compiled function takes the arguments as
    they are, at a fraction of that cost. It does not check them: call it only with arguments of
    exactly these types (the workspace's own objects, or arrays checked for dtype, dimensions and
    layout where they enter); anything else may be misread.
    """
    sig = tuple(dispatcher.typeof_pyval(a) for a in args)
    if sig not in dispatcher.overloads:
        dispatcher.compile(sig)
    return dispatcher.overloads[sig].entry_point
