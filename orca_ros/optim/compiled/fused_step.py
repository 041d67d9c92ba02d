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
The cycle up to the first level's solution in one kernel call: rows, assembly, DAQP's warm solve.

Where the compiled cycle solves its first level by kernel (:mod:`.direct_daqp`), its kernel
calls (:func:`.cycle_kernel.run`, the solve, and for one level :func:`.cycle_kernel.finish`)
and the Python between them become one call of
:func:`.cycle_kernel.step`. What the solve does is the same: the iteration cap from the time
left when the solve starts, the solve timed alone for the solver's time model (both in the
kernel: :mod:`.clock`, :mod:`..solvers.time_model`), a failed warm solve retried cold with
what is left of the cap, then the level's failure handling. Levels below, if any, follow
(:mod:`.cascade`).

Taken only while DAQP's workspace is set up (a warm start): the first solve and the one after
a failure set it up in Python, on the cycle's three-call path; so does a cycle that must
write contact wrench bounds between assembly and solve (a contact changed).
"""

from __future__ import annotations

from . import cycle_kernel
from .cascade_step import CascadeStep
from .step_frame import framed_finish, framed_step, make_frame
from ..solvers import clock, ReturnCode
from ...robot.terms_kernel import cycle_passes
from ...utils.jit import entry

_SUCCESS = ReturnCode.SUCCESS
_NONE = float('inf')  # no deadline


class FusedStep:
    """The one-call cycle of a CompiledCycle (see the module)."""

    def __init__(self, cycle, output):
        self.cycle = cycle
        self.problem = cycle.problem
        self.backend = cycle.problem.backend
        # the controller's solution, accelerations, torques and command (SolutionOutput's: a
        # re-layout of its variables configures the cycle again, and with it this)
        self.outs = (output.x, output.acc, output.tau, output.command)
        self.clock = clock.address()
        # the solution written out by the kernel where no level comes below (else the last
        # level's is, by the controller)
        self.out = int(cycle.cascade is None)
        self.bind(cycle.ws)

    def bind(self, ws) -> None:
        """Compile (or load) the kernel for the workspace's types (again on a new one)."""
        self.ws = ws
        b, cc = self.backend, self.cycle
        self._state = st = b.solve_state  # (replaced by the back-end at a re-configuration)
        self.frame = make_frame(ws, st, b.timing, self.outs, self.clock, b.min_iterations,
                                self.out)
        self.kernel = entry(framed_step, self.frame, 1e-3, 1.0, 1)
        # the last level's solution written out (CompiledCycle.write_out; levels below)
        self.finish_kernel = entry(framed_finish, self.frame, self.outs[0])
        # the lean route (CompiledCycle.run): where a cycle is one Pinocchio pass (two_passes)
        # and this kernel (then the cascade, if levels come below), with nothing else in
        # Python (no contacts, no object updated in Python, no centroidal terms), the cycle
        # runs it inline, without CompiledCycle.update's and this object's frames and tests:
        # on an arm such as the Panda, the Python around a cycle costs more than its kernel
        self.lean = self.cascade_step = None
        if (not cc.python and cc.centroidal is None and cc.two_passes
                and not cc.contacts.owns_layout and not cc.layout.n_wrenches):
            self.lean = (cc.tables.watch, cc.robot, cc.robot.buffers, cc.data, b, st,
                         self.problem, self.frame,
                         cc.derive, cc.robot.model, *cycle_passes())
            if cc.cascade is not None:  # the levels below in the same call
                self.cascade_step = CascadeStep.make(self, cc.cascade)

    def __call__(self, dt: float, deadline, max_iterations) -> ReturnCode:
        """
        Run the cycle from the rows on to the first level's solution; SUCCESS: solved.

        Without levels below, its solution is written out too.

        Any other code is the first level's, as ``CompiledCycle.solve_first`` leaves it before
        the level's failure handling (``PriorityLevels.first_failed``).
        """
        b = self.backend
        if b.solve_state is not self._state:
            self.bind(self.ws)
        b.deadline = deadline
        b.max_iterations = most = max_iterations or b.default_max_iterations
        return self.took(*self.kernel(self.frame, dt,
                                      _NONE if deadline is None else deadline, most))

    def took_solved(self, flags, iters: int) -> None:
        """Take a warm solve's success (the kernel's: the time model updated)."""
        self.backend.iterations = iters
        problem = self.problem
        problem.return_code = _SUCCESS
        problem.built_finite = True
        if flags:
            self.cycle.plan.box_conflicts += flags & 1

    def took(self, flags, flag, iters, cap, ns) -> ReturnCode:
        """Take the kernel's results (see ``__call__``): the solve's code, a failure handled."""
        b, problem = self.backend, self.problem
        if flag == 1:  # the time model updated, the solution written out
            self.took_solved(flags, iters)
            return _SUCCESS
        self.cycle.plan.box_conflicts += flags & 1
        problem.built_finite = flag != cycle_kernel.NOT_BUILT
        if not problem.built_finite:
            code = ReturnCode.NON_FINITE_PROBLEM
        else:
            code = b.ran(flag, iters, ns * 1e-9)
            if code is not _SUCCESS and iters < cap:
                code = b.solve_cold(cap - iters)  # once more, cold
            if code is _SUCCESS and self.out:
                self.cycle.write_out(problem.x)
        problem.return_code = code
        return code
