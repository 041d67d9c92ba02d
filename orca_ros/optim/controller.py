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
The whole-body controller: tasks + constraints -> one QP per cycle -> joint torques.

One class with explicit parts: the objects (:class:`~.task_registry.TaskRegistry`), the variables'
layout (:class:`~.problem_layout.ProblemLayout`), the priorities between levels
(:class:`~.generalized.GeneralizedPriorities`), the solution and command
(:class:`~.solution_output.SolutionOutput`) and the cycle of the current configuration
(:class:`~.reference_cycle.ReferenceCycle`, or the compiled one made from it). Adding or removing
a task or constraint marks the structure changed: the configuration (rows stacked, levels'
problems, solvers set up, kernels lowered) is made again at the next update only then.
``update(t, dt)`` runs the cycle once and makes the command: the solution's, or the safe one.
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from .describe import describe_controller
from .diagnosis import diagnose
from .generalized import GeneralizedPriorities
from .lower_level_problem import DEFAULT_LOWER_LEVEL_DAMPING
from .problem_layout import ProblemLayout
from .reference_cycle import ReferenceCycle
from .resolution_strategy import ResolutionStrategy
from .solution_output import SolutionOutput
from .solvers import QPSolver, resolve_solver, ReturnCode
from .task_registry import TaskRegistry
from .weighted_problem import WeightedProblem
from ..constraint.dynamics_equation_constraint import DynamicsEquationConstraint
from ..constraint.generic_constraint import GenericConstraint
from ..task.generic_task import GenericTask
from ..task.regularisation_task import RegularisationTask
from ..utils.logger import get_logger
from ..utils.optional_import import MissingDependency

_LOG = get_logger('controller')
_SUCCESS = ReturnCode.SUCCESS
_now = time.perf_counter  # (the deadline's clock: the solvers', the kernels')
_said_no_numba = []  # once per process: numba missing, the reference cycle runs


class Controller:
    #: time budget of a new controller's cycles [s]; None: one control period (the dt of each
    #: update). Offline users (tests judging physics, batch simulations) may raise it for all.
    default_time_budget: float | None = None

    def __init__(
        self,
        name: str,
        robot,
        resolution_strategy=ResolutionStrategy.ONE_LEVEL_WEIGHTED,
        solver=QPSolver.DAQP,
        log_solver_fallback: bool = True,
        compiled: bool = True,
    ):
        if robot is None or getattr(robot, 'model', None) is None:
            raise ValueError('Controller needs a RobotModel with a loaded URDF')
        if isinstance(resolution_strategy, str):
            resolution_strategy = ResolutionStrategy.from_string(resolution_strategy)
        if isinstance(solver, str):
            solver = QPSolver.from_string(solver)
        self.name = name
        self.robot = robot
        self.resolution_strategy = resolution_strategy
        # DAQP (the default) has no rosdep key: where it is missing, ProxQP runs and this says why
        self.solver, self.solver_fallback = resolve_solver(solver)
        if self.solver_fallback and log_solver_fallback:
            _LOG.warning(self.solver_fallback)
        self.layout = ProblemLayout(robot)
        # the cycle by numba kernels (optim/compiled/); False: the reference cycle, in Python
        self.compiled = bool(compiled)
        self.cycle: ReferenceCycle | None = None  # made at the first update after a change
        self.priorities = GeneralizedPriorities()
        self.output = SolutionOutput(robot, self.layout)
        # always present, always active: a small regularisation and the equation of motion
        self.global_regularisation = RegularisationTask('GlobalRegularisation')
        self.dynamics_constraint = DynamicsEquationConstraint('DynamicsEquation')
        self.registry = TaskRegistry(name, robot, self.layout,
                                     (self.global_regularisation, self.dynamics_constraint),
                                     self.output.resize)
        self.dropped_levels = 0  # lower priority levels dropped because they could not be solved
        self._solution_found = False
        self._return_code = ReturnCode.NOT_SOLVED
        self._update_cb: Callable[[float, float], None] | None = None
        self._time_budget: float | None = self.default_time_budget
        self._max_iterations: int | None = None  # None: each solver's default
        self._lower_damping = DEFAULT_LOWER_LEVEL_DAMPING

    # -------------------------------------------------------------- configuration
    def _configure(self) -> None:
        """Make the configuration and its cycle: compiled where it can be, else the reference."""
        reference = ReferenceCycle(self.name, self.registry, self.layout,
                                   self.resolution_strategy, self.solver, self._lower_damping,
                                   self.priorities, self.output)
        self.cycle = (self._compile(reference) if self.compiled else None) or reference
        self.registry.dirty = False

    def _compile(self, reference):
        """Lower the reference cycle into the compiled one (None: numba is missing)."""
        try:
            from .compiled import CompiledCycle  # noqa: PLC0415 - numba only when compiled

            cycle = CompiledCycle(reference)
        except MissingDependency as exc:
            if not _said_no_numba:
                _LOG.warning('%s: the reference path runs (slower)', exc)
                _said_no_numba.append(True)
            return None
        _LOG.debug("controller '%s': %s", self.name, cycle.describe())
        return cycle

    @property
    def compiled_cycle(self):
        """Return the compiled cycle (None: not configured yet, or the reference cycle runs)."""
        cycle = self.cycle
        return None if cycle is None or isinstance(cycle, ReferenceCycle) else cycle

    def _levels(self):
        """Return the configuration's priority levels (configured first if it changed)."""
        if self.registry.dirty:
            self._configure()
        return self.cycle.levels

    def get_problem_at_level(self, level: int = 0) -> WeightedProblem:
        """Return the QP of priority level ``level`` (its per-level solution is ``.x``)."""
        for p in self._levels().problems:
            if p.level == level:
                return p
        raise KeyError(
            f"controller '{self.name}': no priority level {level} (levels: {self.get_levels()})"
        )

    def get_levels(self) -> list[int]:
        """Priority levels of the current problem stack (one entry for ONE_LEVEL_WEIGHTED)."""
        return [p.level for p in self._levels().problems]

    def get_level_tasks(self) -> list[list[GenericTask]]:
        """Return the user tasks of each priority level, highest first."""
        return [list(own) for own in self._levels().level_tasks]

    # -------------------------------------------------------------- the cycle
    def update(self, current_time: float, dt: float) -> bool:
        """
        Recompute everything for the robot's current state and solve.

        True when a solution was found: the command (:meth:`get_joint_torque_command`) is the
        solution's. False: no solution (:meth:`get_return_code` says why, :meth:`diagnose` which
        constraints conflict) and the command is the safe one (:meth:`command_is_safe`),
        g(q) - M(q) k_d v clipped to the URDF's torque limits (g left out where the drives
        compensate gravity: :meth:`remove_gravity_torques_from_solution`), the last good command
        fading into it over the ramp from the first failed cycle on (``current_time`` measures the
        fade; :meth:`set_safe_command`, :class:`~orca_ros.safety.SafeCommand`).
        """
        self._solution_found = False
        budget = self._time_budget
        deadline = _now() + (dt if budget is None else budget)
        if self.registry.dirty:  # configuration: solvers set up, their solves not time-bounded
            self._configure()
            deadline = None
        code, dropped = self.cycle.run(current_time, dt, deadline, self._max_iterations)
        self.dropped_levels += dropped
        out = self.output
        if code is _SUCCESS:
            if out.remove_gravity or out.remove_coriolis:
                out.finish_command()
        else:  # the safe command; its fade starts anew at a failure after a success
            out.brake(current_time, self._return_code is _SUCCESS)
            _LOG.debug("controller '%s': no solution at t=%.4f (%s)", self.name, current_time,
                       code.value)
        self._return_code = code
        self._solution_found = found = code is _SUCCESS
        if self._update_cb is not None:
            self._update_cb(current_time, dt)
        return found

    def set_update_callback(self, cb: Callable[[float, float], None]) -> None:
        """Set the callback called at the end of every update(t, dt)."""
        self._update_cb = cb

    on_update_callback = set_update_callback

    def solution_found(self) -> bool:
        return self._solution_found

    def get_return_code(self) -> ReturnCode:
        return self._return_code

    def contacts_relaxed(self) -> bool:
        """Tell whether the last cycle let the contacts slip (see optim/elastic_contacts.py)."""
        return self.cycle is not None and self.cycle.levels.contacts_relaxed

    # -------------------------------------------------------------- tasks and constraints
    def add_task(self, task, name: str | None = None, level: int | None = None):
        """Add a task instance, or build one from its class and name; returns the task."""
        return self.registry.add_task(task, name, level)

    def add_constraint(self, constraint, name: str | None = None):
        """
        Add a constraint instance, or build one from its class and name; returns it.

        A contact brings its wrench variables (6 more QP variables) and its existence condition.
        """
        return self.registry.add_constraint(constraint, name)

    def add_contact(self, contact):
        """Add a contact (as add_constraint does for constraints)."""
        if not getattr(contact, 'is_contact', False):
            raise TypeError(f'add_contact expects a contact, got {type(contact).__name__}')
        return self.registry.add_constraint(contact)

    def get_contacts(self) -> list:
        return list(self.layout.contacts)

    def remove_task(self, name: str) -> None:
        self.registry.remove_task(name)
        self.priorities.forget(name)

    def remove_constraint(self, name: str) -> None:
        self.registry.remove_constraint(name)

    def get_task(self, name: str) -> GenericTask:
        return self.registry.get_task(name)

    def get_constraint(self, name: str) -> GenericConstraint:
        return self.registry.get_constraint(name)

    def get_tasks(self) -> list[GenericTask]:
        """Return the user's tasks (the controller's global regularisation left out)."""
        return self.registry.user_tasks()

    def get_constraints(self) -> list[GenericConstraint]:
        """Return the user's constraints (the equation of motion left out)."""
        return self.registry.user_constraints()

    def activate_tasks_and_constraints(self) -> None:
        for obj in self.get_tasks() + self.get_constraints():
            obj.activate()

    def deactivate_tasks_and_constraints(self) -> None:
        for obj in self.get_tasks() + self.get_constraints():
            obj.deactivate()

    def tasks_and_constraints_deactivated(self) -> bool:
        return all(o.is_deactivated() for o in self.get_tasks() + self.get_constraints())

    # -------------------------------------------------------------- between levels
    def set_priority(self, high: str, low: str, value: float) -> None:
        """
        GENERALIZED: the priority in [0, 1] of task ``high`` over task ``low``.

        0 weighted, 1 strict; may change every cycle. ``high`` must sit on a higher level
        (smaller number) than ``low``.
        """
        if self.resolution_strategy is not ResolutionStrategy.GENERALIZED:
            raise ValueError(
                f"controller '{self.name}': priority values need the GENERALIZED strategy "
                f'(this one is {self.resolution_strategy.value})'
            )
        th, tl = self.get_task(high), self.get_task(low)
        if not th.level < tl.level:
            raise ValueError(
                f"set_priority('{high}', '{low}'): '{high}' (level {th.level}) must be on a "
                f"higher level than '{low}' (level {tl.level})"
            )
        self.priorities.set(high, low, value)

    def set_priority_matrix(self, names, matrix) -> None:
        """
        GENERALIZED: matrix[i][j] = priority of task names[i] over names[j].

        Only entries with level(i) < level(j) are read; the rest must be left at 0 or 1.
        """
        m = np.asarray(matrix, dtype=float)
        if m.shape != (len(names), len(names)):
            raise ValueError(f'priority matrix must be {len(names)}x{len(names)}, got {m.shape}')
        for i, hi in enumerate(names):
            for j, lo in enumerate(names):
                if self.get_task(hi).level < self.get_task(lo).level:
                    self.set_priority(hi, lo, m[i, j])

    def get_priority(self, high: str, low: str) -> float:
        return self.priorities.get(high, low)

    def set_lower_level_damping(self, mu: float) -> None:
        """
        Damp every level below the first in time: + mu W ||x - x_prev||^2 (0: off; default 10).

        W: the level's own weights; see :meth:`LowerLevelProblem.set_temporal_damping`.
        """
        if self.cycle is not None:
            self.cycle.levels.set_temporal_damping(mu)
        self._lower_damping = float(mu)

    # -------------------------------------------------------------- the solves' budget
    def set_solver_budget(
        self, time_budget: float | None = None, max_iterations: int | None = None
    ) -> None:
        """
        Bound every cycle's solves.

        ``time_budget`` seconds for the whole cycle (None: one control period, the dt given to
        update) and at most ``max_iterations`` solver iterations per solve (None: the solver's
        default). A problem the solvers cannot solve within the budget fails with its ReturnCode.
        """
        if time_budget is not None and not (np.isfinite(time_budget) and time_budget > 0.0):
            raise ValueError(
                f"controller '{self.name}': time budget must be > 0 s, got {time_budget}"
            )
        if max_iterations is not None and int(max_iterations) < 1:
            raise ValueError(
                f"controller '{self.name}': max_iterations must be >= 1, got {max_iterations}"
            )
        self._time_budget = None if time_budget is None else float(time_budget)
        self._max_iterations = None if max_iterations is None else int(max_iterations)

    def get_solver_budget(self) -> tuple[float | None, int | None]:
        return self._time_budget, self._max_iterations

    # -------------------------------------------------------------- the solution and command
    def remove_gravity_torques_from_solution(self, do_remove: bool) -> None:
        """
        Subtract g(q) from the torque command (for robots whose drives compensate gravity).

        The safe command of a failed cycle then leaves g(q) out too.
        """
        self.output.set_remove_gravity(do_remove)

    def remove_coriolis_torques_from_solution(self, do_remove: bool) -> None:
        self.output.remove_coriolis = bool(do_remove)

    @property
    def safe_command(self):
        """Return the failed cycle's command (a SafeCommand); None: the caller sends its own."""
        return self.output.safe_command

    @safe_command.setter
    def safe_command(self, value) -> None:
        self.output.safe_command = value

    def set_safe_command(self, damping: float, ramp: float) -> None:
        """
        Set the failed cycle's command: damping k_d [1/s] and fade time ``ramp`` [s].

        tau = g(q) - M(q) k_d v: each joint's speed decays as exp(-k_d t) once the fade is over
        (defaults 10 /s and 0.2 s, as the node's ``safe_damping`` and ``safe_ramp``).
        """
        self.output.set_safe_command(damping, ramp, self.name)

    def command_is_safe(self) -> bool:
        """Tell whether the command is the safe one (the last ``update`` failed)."""
        safe = self.output.safe_command
        return self._return_code is not _SUCCESS and safe is not None and safe.active

    def get_joint_torque_command(self) -> np.ndarray:
        """
        Joint torques to send (gravity/Coriolis removed if asked).

        After a successful ``update``, the solution's; after a failed one, the safe command
        (:meth:`command_is_safe`): bounded by the URDF's torque limits, braking every joint with
        the same time constant 1/k_d, faded in from the last good command.
        """
        return self.output.command.copy()

    def get_joint_acceleration_command(self) -> np.ndarray:
        return self.output.acc[self.layout.joint_acc].copy()

    def get_reduced_solution(self) -> np.ndarray:
        """Return the solver's own variables x = [nu_dot, wrenches]."""
        return self.output.x.copy()

    def get_solution(self) -> np.ndarray:
        """
        Return [base acc, joint acc, base torque, joint torque, wrenches].

        The base parts are empty for a fixed base; torques before any gravity/Coriolis removal.
        """
        return self.output.full_solution()

    def compute_kkt_torques(self) -> np.ndarray:
        """
        Torques of the equality-only problem (no inequality or box constraints).

        From the matrices of the last update: a usable fallback when the QP has no solution.
        """
        x = self._levels().problems[-1].solve_equality_only()
        return self.layout.T @ x + self.layout.t0

    # -------------------------------------------------------------- inspection
    def diagnose(self):
        """Name the constraints that conflict in the last cycle (:mod:`.diagnosis`)."""
        return diagnose(self)

    def print(self) -> None:  # noqa: A003 (ORCA API name)
        print(self.describe())

    def describe(self) -> str:
        return describe_controller(self)
