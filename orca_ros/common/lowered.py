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
Lowered objects: a task or constraint as the compiled cycle's fill kernel computes it.

At configuration, each object of a kind the kernels know gets a row of the fill kernel's table
(``tab[k]`` = [kind, on, a, b, joint]) and, for the kinds with parameters and state, a float
record: the object's own arrays (targets, gains, errors) are rebound to views on that record, so
the Python API (``set_desired``, ``pid().set_proportional_gain``...) writes what the kernel reads,
with no copy per cycle. Every cycle :meth:`Lowered.step` runs the object's life cycle and takes
what the Python API replaced (a new servo, new limits) before the kernel runs.

Each kind's lowered class, its record layout and its row kernel live beside the concept, in a
sibling ``<concept>_kernel.py`` (``task/cartesian_kernel.py`` beside ``task/cartesian_task.py``);
this module holds what they share. Numba-free: the reference path imports nothing compiled.
"""

from __future__ import annotations

import numpy as np

from .task_base import ActivationState

#: the fill kernel's kinds (``tab[k, 0]``)
CART, JOINT, REG, TORQUE, POSITION, VELOCITY, ACCELERATION, COM, MOM = range(9)
TAB = 5  # columns of the fill kernel's table

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)
_ACTIVATED = ActivationState.ACTIVATED


def offset_in(view: np.ndarray, base: np.ndarray) -> int:
    """Index of ``view``'s first element (1-D base) or row (2-D base) in ``base``."""
    if not np.shares_memory(view, base):
        raise AssertionError("an object's rows are not the plan's")
    delta = view.__array_interface__['data'][0] - base.__array_interface__['data'][0]
    return delta // base.strides[0]


class Lowered:
    """
    One object computed by the fill kernel: its table row and its life cycle.

    ``tables`` is the compiled cycle's set of records (``Tables``): ``tab``, ``par`` and one
    record array per kind, with ``take(kind)`` handing out the next record of a kind.
    Subclasses set ``kind`` and ``lowers`` (the exact class they compute), extend :meth:`bind`,
    and override :meth:`refresh` and :meth:`rebind_model` where the object can change.
    """

    kind = -1
    lowers: type | None = None

    def __init__(self, obj):
        self.obj = obj
        self._on = False  # the table's on flag, as last written
        self._par = None  # the table's scalar parameter, as last written

    @staticmethod
    def lowerable(obj, robot) -> str:
        """Why ``obj`` stays in Python although its class is lowered ('' when it does not)."""
        return ''

    def bind(self, tables, k: int, plan) -> None:
        """Take table row ``k``; ``plan`` (the CyclePlan) holds the rows the object writes."""
        self.tables, self.k = tables, k
        tables.tab[k, 0] = self.kind
        tables.tab[k, 1] = 0
        self.obj.watch_by(tables.watch)

    def keep_servoed(self, what: str, own: dict, gains) -> int:
        """
        Take the next record of ``what`` for this servoed task and keep its arrays there.

        ``own``: the task's arrays, name -> start (:meth:`.Watched.keep_in`); ``gains``: the
        starts of its PID's P, I, D, windup limits and integral. The record's index goes into
        the table (``tab[k, 2]``) and is returned.
        """
        tables, task = self.tables, self.obj
        a = tables.take(what)
        rec = tables.record(what, a)
        task.keep_in(rec, own)
        task.pid().keep_in(rec, gains)
        tables.tab[self.k, 2] = a
        return a

    def step(self, t: float) -> None:
        """Advance the activation ramp (as TaskBase.update) and set the table's on flag."""
        obj = self.obj
        st = obj.state
        if st is _ACTIVATED:
            on = True
        elif st in _INACTIVE:
            on = False
        else:
            obj.step_ramp(t)
            on = obj.state not in _INACTIVE
        if on:
            self.refresh()
        if on is not self._on:  # numpy item writes are not free: only on a change
            self.tables.tab[self.k, 1] = on
            self._on = on

    def refresh(self) -> None:
        """Take what the Python API replaced since the last cycle (nothing by default)."""

    def rebind_model(self) -> None:
        """Take what this object read from the robot's model (a new one after a re-weld)."""

    def set_par(self, value: float) -> None:
        """Write the table's scalar parameter of this object (only when it changed)."""
        if value != self._par:
            self.tables.par[self.k, 0] = value
            self._par = value
