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
A cycle's joint command in the fields a robot's drives take: its command interface.

The QP gives the joint torques tau and accelerations a at the measured state (q, v). Each
interface sends a part of what follows, one value per joint and field (:data:`INTERFACES`):

* ``effort``: tau (ros2_control's forward effort convention);
* ``position``, ``velocity``, ``position_velocity``: the reference (q_r, v_r) of
  :class:`.joint_reference.JointReference` (a's integral, leashed to the measured state, within the
  joint limits), for drives that servo a position or a velocity themselves. The cycle then runs
  on the reference, not on the measurement (:meth:`JointCommand.state`): (q_r, v_r) for a
  position drive, (q, v_r) for a velocity one (its position is not servoed: the tasks see where
  the robot is). A QP closed on the measured state of a robot that lags its stiff servos keeps
  accelerating a reference already ahead, and the robot swings around its target; on the
  reference it does not (mc_rtc's integration, leashed);
* ``joint_impedance``: q_r, v_r, a feed-forward torque tau_ff and the gains K_p, K_d of a drive
  that applies tau_ff + K_p (q_r - q) + K_d (v_r - v) at its own rate ("MIT mode" actuators,
  Franka's joint impedance). tau_ff = tau - K_p (q_r - q) - K_d (v_r - v): at the state the QP
  was solved for, the drive applies exactly the torque the QP asked for; between the
  controller's cycles its own loop reacts to what the robot does, at the drive's rate.

The hold (:meth:`JointCommand.held`), for a failed or stale cycle, ``~/enable false`` and the
shutdown: effort, the caller's hold torque (:class:`~orca_ros.safety.SafeCommand`: gravity and
damping, faded in); position, the reference stopped where it was when the hold began (the drive
stops the robot there); velocity, zero; joint impedance, that stopped position with v_r = 0, the
caller's hold torque as tau_ff and the gains (a stiff, damped hold around where the fault found
the robot). After a hold the reference starts again from the measured state.
"""

from __future__ import annotations

import numpy as np

from .joint_reference import JointReference

#: the fields each interface sends, in order
INTERFACES = {
    'effort': ('effort',),
    'position': ('position',),
    'velocity': ('velocity',),
    'position_velocity': ('position', 'velocity'),
    'joint_impedance': ('position', 'velocity', 'effort', 'stiffness', 'damping'),
}


def check_interface(name: str) -> tuple[str, ...]:
    """Return the fields of interface ``name``; ValueError naming the known ones otherwise."""
    if name not in INTERFACES:
        raise ValueError(
            f"command_interface '{name}' is not one of {', '.join(INTERFACES)}"
        )
    return INTERFACES[name]


def joint_gains(what: str, value, n: int) -> np.ndarray:
    """One gain per joint from a scalar or n values, finite and >= 0; ValueError otherwise."""
    g = np.array(value, dtype=float).reshape(-1)
    if g.size == 1:
        g = np.full(n, g[0])
    if g.size != n:
        raise ValueError(f'{what}: {g.size} values for {n} joints')
    if not np.all(np.isfinite(g)) or np.any(g < 0.0):
        raise ValueError(f'{what} must be finite and >= 0, got {g.tolist()}')
    return g


class JointCommand:
    """The command of the robot's n joints in one interface (see the module)."""

    def __init__(self, interface: str, robot, stiffness=None, damping=None,
                 position_leash: float = 0.05, velocity_leash: float = 0.5):
        self.interface = interface
        self.fields = check_interface(interface)
        n = robot.get_nr_of_degrees_of_freedom()
        self.n = n
        self.stiffness = self.damping = None
        if interface == 'joint_impedance':
            if stiffness is None or damping is None:
                raise ValueError('joint_impedance needs joint_stiffness and joint_damping')
            self.stiffness = joint_gains('joint_stiffness', stiffness, n)
            self.damping = joint_gains('joint_damping', damping, n)
        self.reference = None
        if interface != 'effort':
            self.reference = JointReference.of_robot(robot, position_leash, velocity_leash)
        self.values = np.zeros((len(self.fields), n))  # field x joint, model order
        self._row = {f: k for k, f in enumerate(self.fields)}
        self._holding = False
        self._leashed = False  # state() leashed the reference this cycle

    def checked_gains(self, stiffness=None, damping=None):
        """
        Return the joint impedance's gains (K_p, K_d) with the given ones changed, checked.

        Each a scalar or one value per joint, finite and >= 0; None: as it is. ValueError naming
        the cause (another interface sends no gains; a bad value). Nothing changes:
        :meth:`set_gains` applies them.
        """
        if self.stiffness is None:
            raise ValueError(f'the command interface is {self.interface}: it sends no gains')
        n = self.n
        k = self.stiffness if stiffness is None else joint_gains('joint_stiffness', stiffness, n)
        d = self.damping if damping is None else joint_gains('joint_damping', damping, n)
        return k, d

    def set_gains(self, stiffness=None, damping=None) -> None:
        """Change the joint impedance's gains from the next command on (see checked_gains)."""
        self.stiffness, self.damping = self.checked_gains(stiffness, damping)

    def field(self, name: str) -> np.ndarray:
        """Return one field's values (a view of :attr:`values`); KeyError if it is not sent."""
        return self.values[self._row[name]]

    def state(self, q, v):
        """
        Return the joint positions and velocities the cycle runs on, from the measured ones.

        The measured state for efforts and joint impedance; the reference, leashed to the
        measurement, for position drives; the measured positions and the reference's velocities
        for velocity drives. Call it before the cycle's solve, :meth:`solved` after.
        """
        ref = self.reference
        if ref is None or self.interface == 'joint_impedance':
            return q, v
        if self._holding:
            ref.reset()
            self._holding = False
        ref.leash(q, v)
        self._leashed = True
        if self.interface == 'velocity':
            return q, ref.velocity.copy()
        return ref.position.copy(), ref.velocity.copy()

    def solved(self, q, v, tau, acceleration, dt: float) -> np.ndarray:
        """Compute the command of a solved cycle at the measured (q, v); return :attr:`values`."""
        ref = self.reference
        if ref is None:
            self.values[0] = tau
            return self.values
        if self._holding:
            ref.reset()
            self._holding = False
        if not self._leashed:
            ref.leash(q, v)
        self._leashed = False
        ref.integrate(acceleration, dt)
        self._write(ref.position, ref.velocity)
        if self.stiffness is not None:
            self.field('effort')[:] = (
                tau - self.stiffness * (ref.position - q) - self.damping * (ref.velocity - v)
            )
        return self.values

    def held(self, q, hold_torque) -> np.ndarray:
        """Compute the hold (see the module) at measured positions q; return :attr:`values`."""
        ref = self.reference
        if ref is None:
            self.values[0] = hold_torque
            return self.values
        if not ref.started:  # no command yet: hold where the robot is
            ref.advance(q, np.zeros(self.n), np.zeros(self.n), 0.0)
        ref.hold()
        self._holding = True
        self._leashed = False
        self._write(ref.position, ref.velocity)
        if self.stiffness is not None:
            self.field('effort')[:] = hold_torque
        return self.values

    def _write(self, position, velocity) -> None:
        row = self._row
        if 'position' in row:
            self.values[row['position']] = position
        if 'velocity' in row:
            self.values[row['velocity']] = velocity
        if self.stiffness is not None:
            self.values[row['stiffness']] = self.stiffness
            self.values[row['damping']] = self.damping
