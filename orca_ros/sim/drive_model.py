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
Simulated drives: the torque each joint's drive applies, at the simulator's rate, for its command.

A drive's loop runs faster than its controller's: the torque is computed again at every simulation
step from the command last received and the joint's state then (q, v), and clipped to the joint's
effort limit. Per command interface (:data:`orca_ros.command.INTERFACES`):

* ``effort``: tau;
* ``position``, ``velocity``, ``position_velocity``: the servo of a position- or
  velocity-controlled arm, every joint tracking its reference as a critically damped second-order
  system at ``servo_frequency`` f [Hz], w = 2 pi f, whatever the posture and the other joints:

      tau = g(q) + M(q) (w^2 (q_r - q) + 2 w (v_r - v))

  (w^2 term for position drives only, v_r = 0 for position-only ones), M the joints' block of the
  mass matrix at the step's posture, g the gravity torques as feed-forward (a PD alone sags by
  g / K_p). An industrial servo behaves so because its motors' reflected inertia, absent from
  most URDFs, dwarfs the coupling between links; independent PDs on the URDF's inertias instead
  couple the joints into slow, underdamped modes (on 1 / (M^-1)_ii) or stiff ones (on M_ii, beyond
  what an explicit simulation step integrates). Without M (:meth:`DriveModel.torque`), each
  joint's own inertia m_i stands in;
* ``joint_impedance``: tau_ff + K_p (q_r - q) + K_d (v_r - v), the gains the command carries.
"""

from __future__ import annotations

import numpy as np

from ..command import check_interface


class DriveModel:
    """The drives of n joints under one command interface (see the module)."""

    def __init__(self, interface: str, inertia, effort_limit, servo_frequency: float = 20.0):
        self.interface = interface
        self.fields = check_interface(interface)
        inertia = np.asarray(inertia, dtype=float).reshape(-1)
        self.n = inertia.size
        if not (np.isfinite(servo_frequency) and servo_frequency > 0.0):
            raise ValueError(f'servo_frequency must be finite and > 0 Hz, got {servo_frequency}')
        w = self._w = 2.0 * np.pi * float(servo_frequency)
        self.inertia = inertia
        # the servo's gains per joint on its own inertia (joint impedance's hold before a command)
        self.servo_stiffness = inertia * w * w
        self.servo_damping = 2.0 * inertia * w
        lim = np.asarray(effort_limit, dtype=float).reshape(-1)
        self.effort_limit = np.where((lim > 0.0) & np.isfinite(lim), lim, np.inf)
        self.command = np.zeros((len(self.fields), self.n))
        self._row = {f: k for k, f in enumerate(self.fields)}
        self._tau = np.zeros(self.n)

    def set_command(self, values) -> None:
        """Take a command (fields x n, wire order); ValueError for a wrong size or bad values."""
        values = np.asarray(values, dtype=float)
        if values.shape != self.command.shape:
            raise ValueError(
                f'{values.size} values for {len(self.fields)} field(s) '
                f"({', '.join(self.fields)}) of {self.n} joints"
            )
        if not np.all(np.isfinite(values)):
            raise ValueError('non-finite values')
        if 'stiffness' in self._row and (
            np.any(values[self._row['stiffness']] < 0.0)
            or np.any(values[self._row['damping']] < 0.0)
        ):
            raise ValueError('negative stiffness or damping')
        self.command[:] = values

    def torque(self, q, v, gravity, hold: bool = False, mass=None) -> np.ndarray:
        """
        Return the drives' torque at (q, v), the model's gravity torques ``gravity`` (wire order).

        ``mass``: the joints' mass matrix at q (n x n, wire order), for the servos (see the
        module; None: each joint's inertia given at construction).

        ``hold``: the controller went silent (the bridge's watchdog): a drive keeps its last
        position and stops, velocity reference 0 (a velocity drive stops where it is) and, in
        joint impedance, gravity as the feed-forward. The effort interface's hold is the
        caller's (:class:`~orca_ros.safety.CommandWatchdog`).
        """
        tau, c, row = self._tau, self.command, self._row
        vr = 0.0 if hold or 'velocity' not in row else c[row['velocity']]
        if self.interface == 'effort':
            tau[:] = c[0]
        elif self.interface == 'joint_impedance':
            tau[:] = gravity if hold else c[row['effort']]
            tau += c[row['stiffness']] * (c[row['position']] - q) + c[row['damping']] * (vr - v)
        else:
            w = self._w
            acceleration = 2.0 * w * (vr - v)
            if 'position' in row:
                acceleration += w * w * (c[row['position']] - q)
            tau[:] = gravity
            tau += self.inertia * acceleration if mass is None else mass @ acceleration
        np.clip(tau, -self.effort_limit, self.effort_limit, out=tau)
        return tau
