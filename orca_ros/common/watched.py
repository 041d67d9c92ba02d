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

_MISSING = object()


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

    def watch_by(self, flag: Touched | None) -> None:
        """Report changes to ``flag`` (None: to nobody)."""
        object.__setattr__(self, '_watch', flag)
