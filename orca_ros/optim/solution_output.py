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
The controller's solution and command: written out after a solve, read by the caller.

A part of :class:`.controller.Controller` (a mixin: the same object). The solution x of the last
level is turned into accelerations, torques, the command (gravity and Coriolis torques removed
where asked) and the contacts' wrenches (:meth:`_write_out`, or by the compiled cycle's kernel);
the getters return copies. A failed cycle's command is the safe one (:meth:`_command_safe`, the
controller's :class:`~orca_ros.safety.SafeCommand`): a loop that sends the command whatever
``update`` returned brakes the robot instead of holding a torque that no longer fits its state.
"""

from __future__ import annotations

import numpy as np

from .solvers import ReturnCode
from ..safety.safe_command import SafeCommand


class SolutionOutputMixin:
    """The solution's arrays (``_x``, ``_acc``, ``_tau``, ``_tau_cmd``) and what reads them."""

    def remove_gravity_torques_from_solution(self, do_remove: bool) -> None:
        """
        Subtract g(q) from the torque command (for robots whose drives compensate gravity).

        The safe command of a failed cycle then leaves g(q) out too.
        """
        self._remove_gravity = bool(do_remove)
        if self.safe_command is not None:
            self.safe_command.gravity_by_hardware = self._remove_gravity

    def remove_coriolis_torques_from_solution(self, do_remove: bool) -> None:
        self._remove_coriolis = bool(do_remove)

    def _write_out(self, x, cc) -> None:
        """Take the solution x: accelerations, torques, command, the contacts' wrenches."""
        if cc is not None:
            step = cc.fused
            if step is not None:  # its frame holds these arrays: two arguments instead of six
                step._finish(step.frame, x)
            else:
                cc.finish(x, self._x, self._acc, self._tau, self._tau_cmd)
            return
        lay = self.layout
        self._x[:] = x
        self._acc[:] = x[lay.acc]
        np.dot(lay.T, x, out=self._tau)
        self._tau += lay.t0
        self._tau_cmd[:] = self._tau
        for c in lay.contacts:
            c.record_solution(x)

    def _make_command(self) -> None:
        cmd = self._tau_cmd
        cmd[:] = self._tau
        if self._remove_gravity or self._remove_coriolis:
            nb = self.layout.nbase
            g = self.robot.get_generalized_gravity_torques()[nb:]
            if self._remove_gravity:
                cmd -= g
            if self._remove_coriolis:
                cmd -= self.robot.get_generalized_gravity_and_coriolis_torques()[nb:] - g

    def get_joint_torque_command(self) -> np.ndarray:
        """
        Joint torques to send (gravity/Coriolis removed if asked).

        After a successful ``update``, the solution's; after a failed one, the safe command
        (:meth:`command_is_safe`): bounded by the URDF's torque limits, braking every joint with
        the same time constant 1/k_d, faded in from the last good command.
        """
        return self._tau_cmd.copy()

    def command_is_safe(self) -> bool:
        """Tell whether the command is the safe one (the last ``update`` failed)."""
        safe = self.safe_command
        return self._return_code is not ReturnCode.SUCCESS and safe is not None and safe.active

    def set_safe_command(self, damping: float, ramp: float) -> None:
        """
        Set the failed cycle's command: damping k_d [1/s] and fade time ``ramp`` [s].

        tau = g(q) - M(q) k_d v: each joint's speed decays as exp(-k_d t) once the fade is over
        (defaults 10 /s and 0.2 s, as the node's ``safe_damping`` and ``safe_ramp``).
        """
        for what, x in (('damping', damping), ('ramp', ramp)):
            if not (np.isfinite(x) and x >= 0.0):
                raise ValueError(
                    f"controller '{self.name}': safe command {what} must be finite and >= 0, "
                    f'got {x}'
                )
        if self.safe_command is None:  # (switched off by a caller with its own: on again)
            self.safe_command = SafeCommand(self.robot, self._remove_gravity)
        self.safe_command.damping, self.safe_command.ramp = float(damping), float(ramp)

    def _command_safe(self, t: float, after_success: bool) -> None:
        """
        Make the failed cycle's command the safe one at the robot's state (the cycle's).

        ``after_success``: the cycle before succeeded, the fade starts anew from its command.
        """
        safe = self.safe_command
        if safe is None:  # the caller sends its own on a failed cycle (the node)
            return
        if after_success:
            safe.reset()
        self._tau_cmd[:] = safe.compute_at_state(t, self._tau_cmd)

    def get_joint_acceleration_command(self) -> np.ndarray:
        return self._acc[self.layout.joint_acc].copy()

    def get_reduced_solution(self) -> np.ndarray:
        """Return the solver's own variables x = [nu_dot, wrenches]."""
        return self._x.copy()

    def get_solution(self) -> np.ndarray:
        """
        Return the full solution [base acc, joint acc, base torque, joint torque, wrenches].

        The base parts are empty for a fixed base.

        Torques here are the full dynamic torques, before any gravity/Coriolis removal.
        """
        lay = self.layout
        nb = lay.nbase
        return np.concatenate((self._acc, np.zeros(nb), self._tau, self._x[lay.wrench]))

    def compute_kkt_torques(self) -> np.ndarray:
        """
        Return the torques of the equality-only problem.

        Tasks and equalities, no inequality or box constraints, from the matrices of the last
        update.

        A usable fallback when the QP has no solution.
        """
        if self._dirty:
            self._configure()
        x = self._problems[-1].solve_equality_only()
        tau = self.layout.T @ x + self.layout.t0
        return tau
