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
A controller's tasks and constraints: added, named, found and removed.

A part of :class:`.controller.Controller`. Adding or removing one, or a task changing level, marks
the structure changed (:attr:`TaskRegistry.dirty`): the controller configures its plan, levels and
cycle again before its next update. A contact re-lays out the QP variables (six wrench variables
each), which resizes every object and the solution's buffers.
"""

from __future__ import annotations

from ..constraint.generic_constraint import GenericConstraint
from ..task.generic_task import GenericTask


class TaskRegistry:
    """
    The objects of one controller, in the order they were added.

    ``tasks`` and ``constraints`` hold every object, the controller's own two (its global
    regularisation and the equation of motion, ``internal``) first; :meth:`user_tasks` and
    :meth:`user_constraints` leave those out. ``on_relayout`` is called after the layout's
    variables changed (the controller resizes its solution's buffers).
    """

    def __init__(self, owner: str, robot, layout, internal, on_relayout):
        self.owner, self.robot, self.layout = owner, robot, layout
        self.on_relayout = on_relayout
        self.tasks: list[GenericTask] = []
        self.constraints: list[GenericConstraint] = []
        self.internal = tuple(internal)
        self.dirty = True
        for obj in self.internal:
            self._attach(obj)
            (self.tasks if isinstance(obj, GenericTask) else self.constraints).append(obj)
            obj.activate()

    def mark_changed(self) -> None:
        """Mark the structure changed: the controller configures again before its next cycle."""
        self.dirty = True

    def _attach(self, obj) -> None:
        obj.set_robot_model(self.robot)
        obj.resize(self.layout)

    def _add(self, obj, name, base, what: str, into: list):
        """Instantiate ``obj`` from its class and ``name`` if needed, check it, attach it."""
        if isinstance(obj, type):
            if name is None:
                raise ValueError(
                    f'add_{what}({obj.__name__}, name): a name is needed to build the {what}'
                )
            obj = obj(name)
        if not isinstance(obj, base):
            raise TypeError(f'add_{what} expects a {what}, got {type(obj).__name__}')
        if any(o.name == obj.name for o in self.tasks + self.constraints):
            raise ValueError(
                f"controller '{self.owner}': a task or constraint named '{obj.name}' already "
                'exists'
            )
        self._attach(obj)
        if isinstance(obj, GenericTask):
            obj.registry = self
        into.append(obj)
        self.dirty = True
        return obj

    def add_task(self, task, name: str | None = None, level: int | None = None):
        """Add a task instance, or build one from its class and name; returns the task."""
        task = self._add(task, name, GenericTask, 'task', self.tasks)
        if level is not None:
            task.set_priority_level(level)
        return task

    def add_constraint(self, constraint, name: str | None = None):
        """
        Add a constraint instance, or build one from its class and name; returns it.

        A contact brings its wrench variables (6 more QP variables) and its existence condition.
        """
        c = self._add(constraint, name, GenericConstraint, 'constraint', self.constraints)
        if getattr(c, 'is_contact', False):
            for part in c.parts():
                self._add(part, None, GenericConstraint, 'constraint', self.constraints)
            self._relayout()
        return c

    def _relayout(self) -> None:
        """Lay the QP variables out for the current contacts; resize every object."""
        self.layout.set_contacts(
            [c for c in self.constraints if getattr(c, 'is_contact', False)]
        )
        for obj in self.tasks + self.constraints:
            obj.resize(self.layout)
        self.on_relayout()
        self.dirty = True

    def remove_task(self, name: str) -> GenericTask:
        """Remove the task named ``name``; returns it (KeyError: no such task)."""
        task = self.get_task(name)
        self.tasks.remove(task)
        task.registry = None
        self.dirty = True
        return task

    def remove_constraint(self, name: str) -> None:
        c = self.get_constraint(name)
        self.constraints.remove(c)
        if getattr(c, 'is_contact', False):
            for part in c.parts():
                self.constraints.remove(part)
            self._relayout()
        self.dirty = True

    def get_task(self, name: str) -> GenericTask:
        for t in self.tasks:
            if t.name == name:
                return t
        raise KeyError(f"controller '{self.owner}': no task named '{name}'")

    def get_constraint(self, name: str) -> GenericConstraint:
        for c in self.constraints:
            if c.name == name:
                return c
        raise KeyError(f"controller '{self.owner}': no constraint named '{name}'")

    def user_tasks(self) -> list[GenericTask]:
        return [t for t in self.tasks if t not in self.internal]

    def user_constraints(self) -> list[GenericConstraint]:
        return [c for c in self.constraints if c not in self.internal]
