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
The controller's tasks and constraints: added, named, found and removed.

Adding or removing one marks the controller's structure dirty (its plan and levels are rebuilt at
the next update); a contact re-lays out the QP variables (one wrench each), which resizes every
object.
"""

from __future__ import annotations

import numpy as np

from ..constraint.generic_constraint import GenericConstraint
from ..task.generic_task import GenericTask


class TaskRegistryMixin:
    def _attach(self, obj) -> None:
        obj.set_robot_model(self.robot)
        obj.resize(self.layout)

    def _add(self, obj, name, base, what: str, into: list):
        """
        Instantiate ``obj`` from its class and ``name`` if needed.

        Check it and attach it to the robot.
        """
        if isinstance(obj, type):
            if name is None:
                raise ValueError(
                    f'add_{what}({obj.__name__}, name): a name is needed to build the {what}'
                )
            obj = obj(name)
        if not isinstance(obj, base):
            raise TypeError(f'add_{what} expects a {what}, got {type(obj).__name__}')
        if any(o.name == obj.name for o in self._tasks + self._constraints):
            raise ValueError(
                f"controller '{self.name}': a task or constraint named '{obj.name}' already exists"
            )
        self._attach(obj)
        obj._owner = self
        into.append(obj)
        self._dirty = True
        return obj

    def add_task(self, task, name: str | None = None, level: int | None = None):
        """
        Add a task instance, or build one from its class and name.

        Returns the task.
        """
        task = self._add(task, name, GenericTask, 'task', self._tasks)
        if level is not None:
            task.set_priority_level(level)
        return task

    def add_constraint(self, constraint, name: str | None = None):
        """
        Add a constraint instance, or build one from its class and name.

        Returns the constraint. A contact brings its wrench variables (6 more QP variables) and its
        existence condition.
        """
        c = self._add(constraint, name, GenericConstraint, 'constraint', self._constraints)
        if getattr(c, 'is_contact', False):
            for part in c.parts():
                self._add(part, None, GenericConstraint, 'constraint', self._constraints)
            self._set_contacts()
        return c

    def add_contact(self, contact):
        """Add a contact (as add_constraint does for constraints)."""
        if not getattr(contact, 'is_contact', False):
            raise TypeError(f'add_contact expects a contact, got {type(contact).__name__}')
        return self.add_constraint(contact)

    def get_contacts(self) -> list:
        return list(self.layout.contacts)

    def _set_contacts(self) -> None:
        """
        Re-layout the QP variables for the current contacts.

        Every task and constraint is resized.
        """
        self.layout.set_contacts([c for c in self._constraints if getattr(c, 'is_contact', False)])
        for obj in self._tasks + self._constraints:
            obj.resize(self.layout)
        self._x = np.zeros(self.layout.nx)
        self._dirty = True

    def remove_task(self, name: str) -> None:
        self._tasks.remove(self.get_task(name))
        self.priorities.forget(name)
        self._dirty = True

    def remove_constraint(self, name: str) -> None:
        c = self.get_constraint(name)
        self._constraints.remove(c)
        if getattr(c, 'is_contact', False):
            for part in c.parts():
                self._constraints.remove(part)
            self._set_contacts()
        self._dirty = True

    def get_task(self, name: str) -> GenericTask:
        for t in self._tasks:
            if t.name == name:
                return t
        raise KeyError(f"controller '{self.name}': no task named '{name}'")

    def get_constraint(self, name: str) -> GenericConstraint:
        for c in self._constraints:
            if c.name == name:
                return c
        raise KeyError(f"controller '{self.name}': no constraint named '{name}'")

    def get_tasks(self) -> list[GenericTask]:
        return [t for t in self._tasks if t not in self._internal]

    def get_constraints(self) -> list[GenericConstraint]:
        return [c for c in self._constraints if c not in self._internal]
