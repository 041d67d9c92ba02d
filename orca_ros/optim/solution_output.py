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
The controller's solution and command: buffers written after a solve, read by the caller.

A part of :class:`.controller.Controller`. A cycle that solved writes the last level's solution x
into these buffers (:meth:`write_out` on the reference path; the compiled cycle's kernel writes
the same arrays): the accelerations nu_dot = x[acc], the torques tau = T x + t0 (the layout's
torque map), the command (tau, gravity and Coriolis torques removed where the drives compensate
them: :meth:`finish_command`) and each contact's wrench. A failed cycle's command is the safe one
(:meth:`brake`, :class:`~orca_ros.safety.SafeCommand`): a loop that sends the command whatever
``update`` returned brakes the robot instead of holding a torque that no longer fits its state.

Contract: ``x`` (nx), ``acc`` (nv), ``tau`` and ``command`` (ndof) keep their identity while the
layout keeps its variables (the compiled cycle's kernels hold them); :meth:`resize` replaces
``x`` after a re-layout (a contact added or removed), which configures the cycle again.
"""

from __future__ import annotations

import numpy as np

from ..safety.safe_command import SafeCommand


class SolutionOutput:
    """The last solution's buffers and the command made from it (see the module)."""

    def __init__(self, robot, layout):
        self.robot, self.layout = robot, layout
        self.x = np.zeros(layout.nx)
        self.acc = np.zeros(layout.nv)
        self.tau = np.zeros(layout.ndof)
        self.command = np.zeros(layout.ndof)
        self.remove_gravity = False
        self.remove_coriolis = False
        # the failed cycle's command, the node's defaults. None: the caller sends its own after a
        # failed update (the node: its SafeCommand also covers stale states and holds), and a
        # failed cycle leaves the command as it was
        self.safe_command: SafeCommand | None = SafeCommand(robot, damping=10.0, ramp=0.2)

    def resize(self) -> None:
        """Size ``x`` for the layout's variables (after a contact was added or removed)."""
        self.x = np.zeros(self.layout.nx)

    def set_remove_gravity(self, do_remove: bool) -> None:
        """Leave g(q) out of the command, the safe command's included."""
        self.remove_gravity = bool(do_remove)
        if self.safe_command is not None:
            self.safe_command.gravity_by_hardware = self.remove_gravity

    def write_out(self, x) -> None:
        """Take the solution x (the reference path): accelerations, torques, command, wrenches."""
        lay = self.layout
        self.x[:] = x
        self.acc[:] = x[lay.acc]
        np.dot(lay.T, x, out=self.tau)
        self.tau += lay.t0
        self.command[:] = self.tau
        for c in lay.contacts:
            c.record_solution(x)

    def finish_command(self) -> None:
        """Remove g(q) and the Coriolis torques from the command where asked (after write-out)."""
        cmd = self.command
        cmd[:] = self.tau
        nb = self.layout.nbase
        g = self.robot.get_generalized_gravity_torques()[nb:]
        if self.remove_gravity:
            cmd -= g
        if self.remove_coriolis:
            cmd -= self.robot.get_generalized_gravity_and_coriolis_torques()[nb:] - g

    def brake(self, t: float, after_success: bool) -> None:
        """
        Make a failed cycle's command the safe one at the robot's state (the cycle's).

        ``after_success``: the cycle before succeeded, the fade starts anew from its command.
        """
        safe = self.safe_command
        if safe is None:  # the caller sends its own on a failed cycle (the node)
            return
        if after_success:
            safe.reset()
        self.command[:] = safe.compute_at_state(t, self.command)

    def set_safe_command(self, damping: float, ramp: float, owner: str) -> None:
        """Set the safe command's damping k_d [1/s] and fade time [s] (``owner`` names errors)."""
        for what, value in (('damping', damping), ('ramp', ramp)):
            if not (np.isfinite(value) and value >= 0.0):
                raise ValueError(
                    f"controller '{owner}': safe command {what} must be finite and >= 0, "
                    f'got {value}'
                )
        if self.safe_command is None:  # (switched off by a caller with its own: on again)
            self.safe_command = SafeCommand(self.robot, self.remove_gravity)
        self.safe_command.damping, self.safe_command.ramp = float(damping), float(ramp)

    def full_solution(self) -> np.ndarray:
        """Return [base acc, joint acc, base torque (zeros), joint torque, wrenches]."""
        lay = self.layout
        return np.concatenate((self.acc, np.zeros(lay.nbase), self.tau, self.x[lay.wrench]))
