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
Objects that tell a watcher when one of their attributes is set to another object.

The compiled cycle re-reads its tasks' and constraints' Python attributes (activation state,
ramp, weight, limits, targets held or not...) only after one of them changed, instead of every
cycle (:mod:`orca_ros.optim.compiled.cycle`). What the kernels read in place (targets, gains,
the arrays the objects fill) needs no watching; every other change of an object's state goes
through an attribute assignment, whichever method or user code makes it.
"""

from __future__ import annotations

import numpy as np

_MISSING = object()


def keep_in(owner, record: np.ndarray, starts: dict) -> None:
    """
    Keep ``owner``'s arrays in ``record``: each ``owner._<name>`` becomes a view on ``record``.

    ``starts`` maps a name to where its values start in the 1-D ``record``; each array's values
    are copied there first and its shape kept. The owner's methods then read and write the
    record in place, and so does the compiled cycle's kernel that fills the record (the
    lowering of a task, a servo or a PID: :mod:`orca_ros.common.lowered`). Called by the owner
    on itself (``keep_in``): its own fields, its own method.
    """
    for name, start in starts.items():
        attr = '_' + name
        value = np.asarray(getattr(owner, attr), dtype=float)
        view = record[start: start + value.size]
        view[:] = value.reshape(-1)
        object.__setattr__(owner, attr, view.reshape(value.shape))


class Touched:
    """The flag a watcher reads: set by any watched object whose attributes changed."""

    __slots__ = ('touched',)

    def __init__(self):
        self.touched = True


class Watched:
    """Mixin: setting an attribute to a different object sets the watcher's flag."""

    _watch: Touched | None = None

    def __setattr__(self, name, value):
        w = self._watch
        if w is not None and getattr(self, name, _MISSING) is not value:
            w.touched = True
        object.__setattr__(self, name, value)

    def keep_in(self, record: np.ndarray, starts: dict) -> None:
        """Keep this object's arrays named in ``starts`` in ``record`` (see :func:`keep_in`)."""
        keep_in(self, record, starts)

    def watch_by(self, flag: Touched | None) -> None:
        """Report changes to ``flag`` (None: to nobody)."""
        object.__setattr__(self, '_watch', flag)
