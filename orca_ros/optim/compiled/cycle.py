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
The compiled cycle of one controller configuration: lowered objects by kernel, the rest in Python.

Made by the controller at configuration (``Controller(..., compiled=True)``, the default), after
its plan and problems: the kernel is compiled (or loaded from numba's disk cache) here, never in
a control cycle. Per cycle, :meth:`update` runs the Python objects' updates and the lowered
objects' life cycles, then one kernel call (:mod:`.cycle_kernel`) on the cycle's workspace
(:mod:`.workspace`): it replaces the objects' updates, ``CyclePlan.update`` and the first level's
build. Where the only level is solved by kernel and DAQP starts warm, that call solves and writes
the torques out too (:mod:`.fused_step`). The contacts' side is a part,
:class:`~orca_ros.constraint.contact_kernel.LoweredContacts`.
"""

from __future__ import annotations

import time

import numpy as np

from . import cascade, cycle_kernel
from .fused_step import FusedStep
from .lowering import lower, Tables
from .plan_assembly import PlanAssembly
from .workspace import make_workspace
from ..solvers import clock, direct_daqp, QPSolver, ReturnCode
from ...common.lowered import COM, MOM
from ...constraint.balance_constraint import BalanceConstraint
from ...constraint.collision_kernel import attach_kernels
from ...constraint.contact_kernel import LoweredContacts
from ...robot import terms_kernel as terms
from ...robot.centroidal_momentum import CentroidalMomentum
from ...robot.data_views import data_views
from ...robot.state_input import _QUATERNION_TOL
from ...robot.state_input_kernel import StateKernel
from ...utils.jit import entry
from ...utils.logger import get_logger

_LOG = get_logger('compiled')
_SUCCESS = ReturnCode.SUCCESS
_crba, _nle, _WORLD = terms.cycle_passes()
_SOLVED = (_SUCCESS, False)  # run's result where every level solved (none dropped)


class CompiledCycle:
    _said_why = False

    def __init__(self, reference):
        start = time.perf_counter()
        self.reference = reference
        registry, plan = reference.registry, reference.plan
        robot, lay = reference.layout.robot, reference.layout
        self.name, self.levels, self.output = reference.name, reference.levels, reference.output
        self.objects = reference.objects
        self.fused = None  # the one-call cycle (FusedStep), where it applies
        self.python = []  # objects that run their own update, in the reference path's order
        self.lowered = []
        self.in_python: dict[str, str] = {}  # object name -> why it is not lowered
        for obj in self.objects:
            low, why = lower(obj)
            if low is None:
                self.python.append(obj)
                self.in_python[obj.name] = why
            else:
                self.lowered.append(low)
        attach_kernels(registry.constraints, self.python, self.in_python)
        for obj in registry.constraints:  # balance: its polygon and rows by its kernel
            if isinstance(obj, BalanceConstraint):
                obj.use_kernel(obj in self.python)
                if obj in self.python:
                    self.in_python[obj.name] = 'inputs in Python, polygon and rows by kernel'
        self.tables = t = Tables(self.lowered, robot)
        for k, low in enumerate(self.lowered):
            low.bind(t, k, plan)
        for obj in self.objects:  # the lowered ones watch themselves (bind)
            obj.watch_by(t.watch)
        self.n_objects = len(self.objects)
        self.plan = plan
        self.problem = self.levels.problems[0]
        self.assembly = PlanAssembly(plan, self.problem)
        self.robot, self.layout = robot, lay
        self.contacts = LoweredContacts(lay, reference.dynamics, plan, robot.model, self.python,
                                        self.in_python)
        self.python = self.contacts.python
        self._bind_data()
        self.solver_in_kernel = self._solve_in_kernel(reference.solver)
        self.cascade = self._lower_levels(reference.priorities)
        # every level solved by kernel: the cycle's solve instead of the levels'
        self.steady = self.solver_in_kernel and (
            len(self.levels.problems) == 1 or self.cascade is not None
        )
        # compile (or load) the kernel for this configuration's types, every object off: the
        # arrays it writes are rewritten by the first cycle
        t.tab[:, 1] = 0
        self._run(self.ws, 1e-3)
        self._finish(self.ws, np.zeros(lay.nx), np.zeros(lay.nx), np.zeros(lay.nv),
                     np.zeros(lay.ndof), np.zeros(lay.ndof))
        if self.contacts.owns_layout:
            self.contacts.switch_off()
            self._run_contacts(self.ws, 1e-3)
        self.fused = self._fuse()
        self.compile_seconds = time.perf_counter() - start

    def _solve_in_kernel(self, solver) -> bool:
        """
        Give the first level DAQP's C solve by kernel (:mod:`.direct_daqp`).

        When DAQP solves it in its stacked layout (no locked rows) and its C entry points passed
        their check in this process; else the level keeps its back-end and the log says why once.
        """
        problem = self.problem
        if solver is not QPSolver.DAQP or not problem.stacked:
            return False
        why = direct_daqp.unavailable_reason()
        if why is not None:
            if not CompiledCycle._said_why:
                _LOG.warning('%s: the first level is solved through the daqp package', why)
                CompiledCycle._said_why = True
            return False
        lay = self.layout
        problem.backend = b = direct_daqp.DirectDAQPBackend(
            lay.nx, problem.n_eq, problem.n_in, scale=lay.variable_scale
        )
        plan = self.plan
        b.write_into(problem.x)
        b.compile_for(problem.H, problem.g, plan.M, plan.lo, plan.hi)
        return True

    def _fuse(self):
        """Make the one-call cycle (FusedStep): the first level solved by kernel, bounds too."""
        if not self.steady:
            return None
        if self.plan.contacts and not self.contacts.owns_layout:
            return None  # the contacts' wrench bounds may change on any cycle (update)
        why = clock.unavailable_reason()
        if why is not None:
            self.in_python['the one-call cycle'] = why
            return None
        return FusedStep(self, self.output)

    def _lower_levels(self, priorities):
        """Lower the levels below the first (None: one level, or they cannot be)."""
        levels = self.levels
        if not self.solver_in_kernel or len(levels.problems) == 1:
            return None
        why = cascade.unlowered_reason(levels)
        if why is not None:
            self.in_python['the levels below the first'] = why
            return None
        return cascade.CompiledCascade(self, levels, priorities)

    def _bind_data(self) -> None:
        """
        Take the robot's Pinocchio Data (its live arrays) and model (bodies, frames).

        Again whenever the robot replaces them: re-welding locked joints that moved
        (``RobotModel.set_locked_joint_positions``) makes a new model and Data.
        """
        robot, lay, t = self.robot, self.layout, self.tables
        d, nb = robot.data, lay.nbase
        views = data_views(robot.model, d)
        if views is None:
            raise RuntimeError("Pinocchio's Data is not laid out as the kernels read it")
        self.data = d
        # the Pinocchio pass: two passes where they give all the kernels read (terms_kernel)
        self.derive = np.zeros(1, dtype=np.int64)
        self._gravity = robot.model.gravity.linear.copy()
        self._pass_stamp = None
        self.two_passes = (
            not self.python
            and not any(low.kind == COM for low in self.lowered)
            and terms.matches(robot.model, lambda data: data_views(robot.model, data))
        )
        # momentum tasks: the robot's centroidal terms (dccrba, once per state: kernel and API)
        self.centroidal, cm_terms = None, (np.zeros((6, lay.nv)), np.zeros(6), np.zeros(6))
        if any(low.kind == MOM for low in self.lowered):
            self.centroidal = cm = CentroidalMomentum.of(robot)
            cm_terms = cm.Ag, cm.h, cm.drift
        buf = robot.buffers
        if buf.state_kernel is None:  # a new robot model comes without it
            buf.state_kernel = StateKernel(robot, _QUATERNION_TOL)
        t.set_bodies(robot.model)
        for low in self.lowered:
            low.rebind_model()
        # the torque map (T, t0): Pinocchio's M and nle themselves without contacts (what
        # layout.update points to every cycle), the layout's own arrays with contacts
        T, t0 = (d.M[nb:], d.nle[nb:]) if lay.n_wrenches == 0 else (lay.T_own, lay.t0_own)
        if lay.n_wrenches == 0:
            lay.T, lay.t0 = T, t0  # what layout.update sets: update() calls it no more
        self.ws = make_workspace(
            J=d.J, oMi=views[0], vj=views[1], aj=views[2], a_gf=views[3], grav=self._gravity,
            derive=self.derive, q=buf.q, v=buf.v,
            v_pin=buf.v_pin, T=T, t0=t0, cart=t.cart, cart_sup=t.cart_sup, jrec=t.jrec,
            lims=t.lims, pacc=t.pacc, tab=t.tab, par=t.par, tmp=t.tmp,
            com=d.com[0], vcom=d.vcom[0], Jcom=d.Jcom, body=t.body, crec=t.crec,
            Ag=cm_terms[0], hg=cm_terms[1], dhg=cm_terms[2], mrec=t.mrec,
            M_pin=d.M, nle=d.nle, **self.contacts.arrays(), **self.assembly.arrays(),
        )
        # the kernels for this workspace's types, called without the dispatcher's type
        # resolution (utils.jit.entry: it types the workspace anew at every call); the
        # finish kernel's arrays are the controller's and the levels' solutions (float64, 1-D)
        ws = self.ws
        self._run = entry(cycle_kernel.run, ws, 1e-3)
        self._run_contacts = entry(cycle_kernel.run_contacts, ws, 1e-3)
        vec = np.zeros(1)
        self._finish = entry(cycle_kernel.finish, ws, vec, vec, vec, vec, vec)
        if self.fused is not None:
            self.fused.bind(ws)

    def run(self, t: float, dt: float, deadline, max_iterations):
        """
        Run the cycle, as :meth:`.ReferenceCycle.run` does (same arguments, same results).

        Where nothing changed since the last cycle and the one-call cycle applies with nothing
        else in Python (``FusedStep.lean``), the lean route: Pinocchio's two passes, then one
        kernel call up to the first level's solution (and the levels below: ``cascade_step``),
        inline here. Else :meth:`update`, then the levels' solves by kernel (:meth:`solve`)
        where every level is lowered, else the levels' own; then the solution written out.
        """
        step = self.fused
        lean = None if step is None else step.lean
        fused = solved = None
        if lean is not None:
            watch, r, buf, data, b, st, problem, frame, derive, model, crba, nle, world = lean
            if watch.touched or r.data is not data or b.solve_state is not st or not b.warm:
                lean = None
        if lean is not None:
            stamp = buf.stamp
            if stamp != self._pass_stamp and buf.terms_stamp != stamp:
                q = buf.q_pin
                crba(model, data, q, world)  # (terms.two_passes)
                nle(model, data, q, buf.v_pin)
                derive[0] = 1  # the kernel derives the drifts
                self._pass_stamp = stamp
            most = max_iterations or b.default_max_iterations
            cstep = step.cascade_step
            if cstep is not None:  # the levels below in the same call (CascadeStep)
                steady = not cstep.changed.touched
                if not steady:
                    cstep.write_modes()
                flags, k, iters = cstep.run(cstep.frame, dt, deadline, most)
                if k > cstep.n and steady:  # every level solved as the last cycle, written out
                    b.iterations = iters
                    if flags:
                        self.plan.box_conflicts += flags & 1
                    return _SOLVED
                solved = cstep.took(flags, k, iters, deadline, most, max_iterations, self.name,
                                    self.levels)
                if solved is True:  # every level solved, written out
                    return _SOLVED
            else:
                flags, flag, iters, cap, ns = step.kernel(frame, dt, deadline, most)
                if flag == 1:  # FusedStep.took_solved, inline (the Panda's cycle notices)
                    b.iterations = iters
                    problem.return_code = fused = _SUCCESS
                    problem.built_finite = True
                    if flags:
                        self.plan.box_conflicts += flags & 1
                else:  # (b's budget: what a failure's handling reads)
                    b.deadline, b.max_iterations = deadline, most
                    fused = step.took(flags, flag, iters, cap, ns)
        else:
            fused = self.update(t, dt, deadline, max_iterations)
        levels = self.levels
        if solved is not None:
            problem, code, dropped = solved
        elif fused is _SUCCESS and self.cascade is None:  # solved and written out
            levels.contacts_relaxed = False
            return _SOLVED
        elif self.steady or fused is not None:  # every level by kernel
            problem, code, dropped = self.solve(levels, deadline, max_iterations, self.name,
                                                fused)
        else:
            problem, code, dropped = levels.solve(deadline, max_iterations,
                                                  self.reference.priorities, self.name)
        if code is _SUCCESS:
            self.write_out(problem.x)
        return code, dropped

    def write_out(self, x) -> None:
        """Write the solution x into the output's buffers (accelerations, torques, wrenches)."""
        step = self.fused
        if step is not None:  # its frame holds the output's arrays
            step.finish_kernel(step.frame, x)
        else:
            out = self.output
            self._finish(self.ws, x, out.x, out.acc, out.tau, out.command)

    def update(self, t: float, dt: float, deadline=None, max_iterations=None):
        """
        Fill every object's rows and assemble the plan.

        What the reference path's object loop, CyclePlan.update and the first level's build do.
        Where the cycle takes one call (``fused``), it solves and writes the solution out too:
        then it returns the first level's ReturnCode (see FusedStep), else None.
        """
        if self.robot.data is not self.data:
            self._bind_data()
        # full: an object changed since the last cycle's updates, or changes in this one's (a
        # ramp in progress: then the next cycle is full too, the flag stays set)
        watch = self.tables.watch
        full = watch.touched
        watch.touched = False
        if self.contacts.owns_layout or not self.layout.n_wrenches:
            # this cycle's Pinocchio pass (terms_kernel): two passes, or computeAllTerms (inline: a
            # method's frame spared at every cycle); (T, t0) are views on Pinocchio's M and
            # nle (_bind_data) without contacts
            r = self.robot
            buf = r.buffers
            if not self.two_passes:
                r.update_terms()
            elif buf.stamp != self._pass_stamp and buf.terms_stamp != buf.stamp:
                model, d, q = r.model, r.data, buf.q_pin
                _crba(model, d, q, _WORLD)
                _nle(model, d, q, buf.v_pin)  # (terms.two_passes)
                self.derive[0] = 1  # the first kernel derives the drifts
                self._pass_stamp = buf.stamp
            if self.contacts.owns_layout:  # (ProblemLayout.update's, on the reference path)
                if full:  # (what else changes from cycle to cycle is the kernel's)
                    self.contacts.update(t, dt)
                self._run_contacts(self.ws, dt)
        else:
            self.layout.update()
        for obj in self.python:
            obj.update(t, dt)
        if self.centroidal is not None:  # the momentum tasks' terms (cached per state)
            self.centroidal.terms()
        full = full or watch.touched
        if full:  # else no object changed: nothing to re-read
            for low in self.lowered:
                low.step(t)  # a ramp in progress touches its object: stepped again next cycle
            self.assembly.flags()
            if self.cascade is not None:
                self.cascade.flags()
        fused = self.fused
        if fused is not None and fused.backend.warm and not (full and self.plan.contacts):
            return fused(dt, deadline, max_iterations)
        flags = self._run(self.ws, dt)
        self.plan.box_conflicts += flags & 1
        self.problem.built_finite = not flags & 2
        if self.plan.contacts and (full or not self.contacts.owns_layout):
            # the wrench bounds (the kernel writes the joints' only): they change with the
            # contacts' state (lowered contacts: after a change; else their updates may any time)
            self.assembly.contacts()

    def solve(self, levels, deadline, max_iterations, name: str, first=None):
        """
        Solve every level by kernel (when ``steady``), as ``levels.solve`` returns.

        ``first``: the first level's code where update() solved it (the one-call cycle): a
        failure, or a success with levels below (one level's success is the controller's own
        to take: its solution is written out already).
        """
        if first is None:
            if self.cascade is not None:
                return self.cascade.solve(deadline, max_iterations, name)
            return self.solve_first(levels, deadline, max_iterations)
        levels.contacts_relaxed = False
        if first is not _SUCCESS:
            return levels.first_failed(self.problem, first, deadline, max_iterations)
        return self.cascade.solve(deadline, max_iterations, name, self.problem)

    def solve_first(self, levels, deadline, max_iterations):
        """
        Solve the first level by kernel, as ``levels.solve`` returns for it.

        What PriorityLevels.solve and WeightedProblem.solve do for it (the budget, the check of
        the built problem, the solve, the code kept, elastic contacts after a failure), without
        their layers: its H and g are built and the back-end writes the level's x
        (DirectDAQPBackend.write_into).
        """
        levels.contacts_relaxed = False
        problem = self.problem
        if problem.built_finite:
            b = problem.backend
            b.deadline = deadline
            b.max_iterations = max_iterations or b.default_max_iterations
            code = b.solve_bound()
        else:
            code = ReturnCode.NON_FINITE_PROBLEM
        problem.return_code = code
        if code is not ReturnCode.SUCCESS:
            return levels.first_failed(problem, code, deadline, max_iterations)
        return problem, code, False

    def describe(self) -> str:
        rest = ', '.join(f'{n} ({why})' for n, why in self.in_python.items())
        return (
            f'compiled cycle: {len(self.lowered)} of {self.n_objects} objects by kernel'
            + (f'; in Python: {rest}' if rest else '')
            + ('; Pinocchio: crba and nonLinearEffects' if self.two_passes else '')
            + ('; first level solved by DAQP in the kernel' if self.solver_in_kernel else '')
            + (f'; the {len(self.cascade.lower)} level(s) below too' if self.cascade
               else '')
            + f' (kernels ready in {self.compile_seconds:.2f} s)'
        )
