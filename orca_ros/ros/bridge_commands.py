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
The simulator bridge's command side: the commands it takes, and what its drives apply.

A part of :class:`.sim_bridge.SimBridge`. ``command_interface`` [effort] names what the simulated
drives take (:data:`orca_ros.command.INTERFACES`, the wire layouts of :mod:`.command_wire`):
``effort``, torques applied as they are (clipped to the effort limits); ``position``,
``velocity``, ``position_velocity``, servos critically damped at ``servo_frequency`` [20 Hz]
whatever the posture (on the joints' mass matrix of each step), gravity as feed-forward;
``joint_impedance``, the drive law with the gains of each command. The drives run at the
simulator's own rate: their torque is computed again before every simulation step
(:class:`orca_ros.sim.drive_model.DriveModel`), several per command when ``control_period``
spans several steps.

Without a command for ``command_timeout`` (free running), the effort drives fade into gravity
and damping (:class:`orca_ros.safety.CommandWatchdog`); the others hold where their last command
put them (velocity reference 0; in joint impedance, gravity as the feed-forward). A command that
does not fit (its size, its fields, its joints' names, NaN, negative gains) is refused with a
throttled line naming the cause; the last valid one stays. Commands come as ``command_message``
says (:mod:`.command_wire`): Float64MultiArray, or JointState by name (in joint impedance the
drives then apply their own ``joint_stiffness`` and ``joint_damping``).
"""

from __future__ import annotations

import numpy as np

from .command_wire import command_wire
from ..command import check_interface, joint_gains
from ..sim.drive_model import DriveModel


class BridgeCommands:
    """What the bridge's drives apply (see the module)."""

    def __init__(self, say, sim_model, joints, cmd_map, robot_model, model_map, model_state,
                 interface: str, servo_frequency: float, watchdog, hw_gravity: bool,
                 time_step: float, message: str = 'float64_multi_array', gains=(None, None)):
        self.say = say
        self.sim_model = sim_model
        self.joints = list(joints)
        self.cmd_map = cmd_map
        self.interface = interface
        self.fields = check_interface(interface)
        self.wire = command_wire(message, self.fields, self.joints, False)
        # the gains a JointState command does not carry: the drive's own (joint impedance)
        self._own_gains = None
        if message == 'joint_state' and interface == 'joint_impedance':
            if gains[0] is None or gains[1] is None:
                raise ValueError('joint_impedance commands as joint_state carry no gains: the '
                                 'bridge needs joint_stiffness and joint_damping')
            n = len(self.joints)
            self._own_gains = (joint_gains('joint_stiffness', gains[0], n),
                               joint_gains('joint_damping', gains[1], n))
        self.watchdog = watchdog
        self.hw_gravity = hw_gravity
        self._model_state = model_state  # copies the simulated state into robot_model
        self._robot_model = robot_model
        self._model_map = model_map
        self._wire_of_model = np.array(
            [robot_model.get_joint_names().index(j) for j in self.joints], dtype=int
        )
        n = len(self.joints)
        limits = sim_model.get_joint_effort_limits()[cmd_map.sim_index]
        self.effort_limit = np.array([e if e > 0 else np.inf for e in limits])
        self.effort = np.zeros(n)  # the effort interface's last valid command
        self.drive = None
        self._servos = interface not in ('effort', 'joint_impedance')
        if interface != 'effort':
            self._model_state()
            self.inertia = self._joint_inertia()
            self.drive = DriveModel(interface, self.inertia, self.effort_limit, servo_frequency)
            self.drive.set_command(self._at_rest())
        self.time_step = float(time_step)
        self.holding = False  # the drives' hold (interfaces other than effort)
        self.timeout = watchdog.timeout if watchdog is not None else None

    def _joint_inertia(self) -> np.ndarray:
        """Each joint's inertia with the others free (a floating base too), 1 / (M^-1)_ii."""
        rm = self._robot_model
        ndof = rm.get_nr_of_degrees_of_freedom()
        return (1.0 / np.diag(np.linalg.inv(rm.get_mass_matrix()))[-ndof:])[self._wire_of_model]

    def _at_rest(self) -> np.ndarray:
        """
        Return the command that holds the drives where the robot is (before the first command).

        In joint impedance with the servos' gains (a command carries its own).
        """
        values = np.zeros((len(self.fields), len(self.joints)))
        row = {f: k for k, f in enumerate(self.fields)}
        if 'position' in row:
            values[row['position']] = self.sim_model.get_joint_positions(self.cmd_map)
        if 'stiffness' in row:
            values[row['stiffness']] = self.drive.servo_stiffness
            values[row['damping']] = self.drive.servo_damping
        return values

    def take(self, msg, t: float) -> bool:
        """Take a command at simulated time t; False (refused, the cause said) if it is bad."""
        try:
            values = self.wire.read(msg)
            if self._own_gains is not None:
                values[3], values[4] = self._own_gains
            if not np.all(np.isfinite(values)):
                raise ValueError('non-finite values')
            if self.drive is not None:
                self.drive.set_command(values)
        except ValueError as exc:
            cause = 'command:nan' if 'finite' in str(exc) else 'command:size'
            self.say('error', cause, f'rejected {self.interface} command ({exc}); keeping the '
                     'last valid command')
            return False
        if self.drive is None:
            self.effort = np.clip(values[0], -self.effort_limit, self.effort_limit)
        elif self.interface == 'joint_impedance':
            self._tell_stiff(values[3], values[4])
        if self.watchdog is not None and self.watchdog.on_command(t, self.effort):
            self.say('info', 'watchdog:resume', 'effort commands resumed: hold released')
        if self.holding:
            self.holding = False
            self.say('info', 'watchdog:resume', f'{self.interface} commands resumed')
        return True

    def _tell_stiff(self, stiffness, damping) -> None:
        """
        Say which joints' gains the simulation step cannot integrate stably (throttled).

        A drive's damping K_d on a joint of inertia m, integrated explicitly over a step dt, is
        stable up to K_d dt / m = 2, its stiffness up to K_p dt^2 / m = 4 (less together); a
        real drive's rotor inertia (absent from most URDFs) makes light joints far heavier.
        """
        dt, m = self.time_step, self.inertia
        stiff = (damping * dt / m > 1.0) | (stiffness * dt * dt / m > 1.0)
        if stiff.any():
            names = [j for j, s in zip(self.joints, stiff) if s]
            self.say('warning', 'command:stiff', f'joint_impedance gains of {names} beyond what '
                     f'a {dt * 1e3:.2g} ms simulation step integrates stably (K_d dt / m > 1 or '
                     'K_p dt^2 / m > 1, m the joint inertia): the simulated drive may oscillate')

    def reset(self) -> None:
        """Zero the effort, the drives holding the robot where it is (put back at its start)."""
        self.effort[:] = 0.0
        if self.drive is not None:
            self.drive.set_command(self._at_rest())

    def before_step(self, t: float, first: bool) -> None:
        """Set the torques of the next simulation step (``first``: the first of this command)."""
        if self.drive is None:
            if first:
                self.sim_model.set_joint_torque_command(self._watched_effort(t), self.cmd_map)
            return
        wd = self.watchdog
        if wd is not None and wd.expired(t) and not self.holding:
            self.holding = True
            silence = wd.silence(t)
            self.say('warning', 'watchdog:hold',
                     f'no {self.interface} command yet: the drives hold where they are'
                     if silence is None else
                     f'no {self.interface} command for {silence * 1e3:.0f} ms (command_timeout '
                     f'{self.timeout * 1e3:.0f} ms): the drives hold the last position')
        q = self.sim_model.get_joint_positions(self.cmd_map)
        v = self.sim_model.get_joint_velocities(self.cmd_map)
        gravity, mass = 0.0, None
        if self._servos or not self.hw_gravity:
            self._model_state()
        if self._servos:  # critically damped at the posture now (see DriveModel)
            rm, w = self._robot_model, self._wire_of_model
            ndof = rm.get_nr_of_degrees_of_freedom()
            mass = rm.get_mass_matrix()[-ndof:, -ndof:][np.ix_(w, w)]
        if not self.hw_gravity:  # else the simulated drives add it themselves
            gravity = self._robot_model.get_joint_gravity_torques()[self._wire_of_model]
        tau = self.drive.torque(q, v, gravity, hold=self.holding, mass=mass)
        self.sim_model.set_joint_torque_command(tau, self.cmd_map)

    def _watched_effort(self, t: float) -> np.ndarray:
        """Return the last effort command, or the watchdog's hold once none came in time."""
        wd = self.watchdog
        if wd is None or not wd.expired(t):
            return self.effort
        if not wd.holding:
            silence = wd.silence(t)
            self.say(
                'warning',
                'watchdog:hold',
                'no effort command yet: holding (gravity + damping)'
                if silence is None
                else f'no effort command for {silence * 1e3:.0f} ms (command_timeout '
                f'{self.timeout * 1e3:.0f} ms): holding (gravity + damping)',
            )
        q, v = self._model_state()
        return wd.hold(t, q, v)
