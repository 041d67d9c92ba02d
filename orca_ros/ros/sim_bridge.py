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
Simulator bridge node: the simulated robot behind ros2_control-style topics.

One node for both worlds: ``pybullet_bridge`` (:mod:`orca_ros.ros.pybullet_bridge`) and
``mujoco_bridge`` (:mod:`orca_ros.ros.mujoco_bridge`, :mod:`orca_ros.sim.mujoco_server`), the same
parameters, topics, services and behaviour; what the two engines do differently (contacts,
friction, joint stops, servos) is told in docs/tutorials/simulation.md.

Publishes ``joint_states`` (name, position, velocity (none with ``publish_velocities: false``, as
a driver that measures positions only), effort), ``odom`` (nav_msgs/Odometry,
floating base only, twist in the child frame as the message defines; none with
``publish_odom_twist: false``: covariance[0] = -1, unknown) and ``/clock`` (simulated
time); takes commands on ``command_topic`` [``/<controller_name>/commands``] (efforts by default:
std_msgs/Float64MultiArray in the ``joints`` order, reliable QoS, as ros2_control's forward effort
controller; other interfaces and JointState commands: :mod:`.bridge_commands`), so a real robot
replaces this node by a parameter change. Joints of the URDF outside ``joints`` (a gripper's) are
held by the simulator's position motor at ``held_joint_positions``, as their own driver would, and
published after the commanded ones. The simulator is addressed by joint names throughout (its own
joint order is the URDF file's, not Pinocchio's).

Modes: ``free_running`` (the simulation advances at wall-clock rate ``rate``) and ``lockstep``
(each command advances the simulation by ``control_period`` and answers with the new state:
deterministic runs). Waiting for a command, lockstep announces the state again every 0.2 s (a
controller started late, a state lost); the controller answers a repeated state with its command
of that instant again, so a controller that was only slow sends it twice. A command that names
the state it answers (its layout's label, see ``common.ANSWERS``: this package's controller does
in lockstep) steps only the instant it names; one that names none steps on arrival. Services:
``~/reset``, ``~/pause``, ``~/unpause`` (std_srvs/Trigger). Obstacles: the controller's
``~/obstacles`` markers become static bodies (``obstacles_topic``; :mod:`.sim_obstacles`). Pushes:
a force on a link from ``~/external_force`` (geometry_msgs/WrenchStamped; :mod:`.sim_push`).

Watchdog (free running): without a valid command for ``command_timeout`` [0.02 s of simulated time]
the bridge holds the robot like a drive would (the last command fades over ``hold_ramp`` [0.05 s]
into gravity + damping ``hold_damping`` [20 /s], see :class:`orca_ros.safety.CommandWatchdog`),
says so once, and applies the next command as soon as it arrives. Before the first command it holds
too, and a floating base (``hold_base_until_command`` [true], free running) is held where it was
placed (:class:`orca_ros.sim.BaseHold`: gravity compensation of the joints does not hold a standing
robot up), released over ``base_release`` [0.2 s of simulated time] once the first command arrives.
"""

from __future__ import annotations

from nav_msgs.msg import Odometry
import numpy as np
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from std_srvs.srv import Trigger

from .bridge_commands import BridgeCommands
from .common import (
    COMMAND_QOS,
    DESCRIPTION_QOS,
    param,
    sec_to_stamp,
    stamp_ns,
    STATE_QOS,
)
from .guarded_node import GuardedNode
from .odometry import odometry
from .sim_obstacles import SimObstacles
from .sim_push import SimPush
from ..configuration import resolve_urdf_path
from ..robot import RobotModel
from ..safety import CommandWatchdog
from ..sim import SimServer


def _world(simulator: str):
    """Return the world class of ``simulator`` (MuJoCo's imported only when asked for)."""
    if simulator == 'mujoco':
        from ..sim.mujoco_server import MujocoServer  # noqa: PLC0415 - optional simulator

        return MujocoServer
    return SimServer


class SimBridge(GuardedNode):
    #: the simulator: 'pybullet' or 'mujoco' (the node is named <simulator>_bridge)
    SIMULATOR = 'pybullet'

    def __init__(self, **kwargs):
        super().__init__(
            f'{self.SIMULATOR}_bridge', automatically_declare_parameters_from_overrides=True,
            **kwargs
        )
        urdf = param(self, 'urdf_path', 'lwr.urdf')
        description = param(self, 'robot_description', '')
        self.floating = bool(param(self, 'floating_base', False))
        self.mode = str(param(self, 'mode', 'free_running'))
        if self.mode not in ('free_running', 'lockstep'):
            raise ValueError(f"mode must be free_running or lockstep, got '{self.mode}'")
        self.time_step = float(param(self, 'time_step', 0.001))
        self.control_period = float(param(self, 'control_period', 0.001))
        self.rate = float(param(self, 'rate', 1000.0))
        self.hw_gravity = bool(param(self, 'gravity_compensation', False))
        self.publish_clock = bool(param(self, 'publish_clock', self.mode == 'lockstep'))
        # false: joint_states without velocities, as a driver that measures positions only
        self.publish_velocities = bool(param(self, 'publish_velocities', True))
        # false: odom without a twist (zeros, covariance[0] = -1: unknown), as odometry from poses
        self.publish_odom_twist = bool(param(self, 'publish_odom_twist', True))
        self.stop_time = float(
            param(self, 'stop_time', 0.0)
        )  # > 0: simulated time at which stepping stops
        controller_name = str(param(self, 'controller_name', 'effort_controller'))
        description_given = bool(description)
        if description:
            import tempfile  # noqa: PLC0415

            fh = tempfile.NamedTemporaryFile('w', suffix='.urdf', delete=False)
            fh.write(description)
            fh.close()
            urdf = fh.name
        else:
            urdf = resolve_urdf_path(urdf)
            with open(urdf) as fh:
                description = fh.read()
        # the URDF for controllers started without one (robot_state_publisher's topic and QoS)
        self.pub_description = self.create_publisher(String, 'robot_description', DESCRIPTION_QOS)
        self.pub_description.publish(String(data=description))
        self.server = _world(self.SIMULATOR)(
            gui=bool(param(self, 'gui', False)),
            time_step=self.time_step,
            ground_plane=bool(param(self, 'ground_plane', True)),
        )
        self.model = self.server.insert_model_from_urdf_file(
            urdf,
            param(self, 'base_position', [0.0, 0.0, 0.0]),
            param(self, 'base_orientation', [0.0, 0.0, 0.0, 1.0]),
            fixed_base=not self.floating,
        )
        names = self.model.get_joint_names()
        self.joints = joints = list(param(self, 'joints', names) or names)
        self.initial = np.array(
            param(self, 'initial_positions', [0.0] * len(joints)) or [0.0] * len(joints),
            dtype=float,
        )
        if self.initial.size != len(joints):
            raise ValueError(f'initial_positions needs {len(joints)} values')
        self.model.set_model_configuration(joints, self.initial)
        self._cmd_map = self.model.joint_map(joints)
        # joints nobody commands here (a gripper's): its own driver, PyBullet's position motor,
        # holds them; joint_states carries them after the commanded ones
        self.held = [n for n in self.model.get_joint_names() if n not in joints]
        self.held_positions = np.array(
            param(self, 'held_joint_positions', [0.0] * len(self.held)) or [0.0] * len(self.held),
            dtype=float,
        )
        if self.held_positions.size != len(self.held):
            raise ValueError(f'held_joint_positions needs {len(self.held)} values ({self.held})')
        if self.held:
            self.model.set_model_configuration(self.held, self.held_positions)
            self.model.set_joint_position_servo(self.held, self.held_positions)
        self._state_map = self.model.joint_map(joints + self.held)
        # the hardware's own model (Pinocchio, same URDF): emulated gravity compensation and the
        # watchdog's hold
        self.robot_model = RobotModel()
        self.robot_model.load_model_from_file(urdf, self.floating)
        self._model_map = self.model.joint_map(self.robot_model.get_joint_names())
        self.command_timeout = float(param(self, 'command_timeout', 0.02))
        self.watchdog = None
        if self.mode == 'free_running':  # lockstep: the simulation only advances on commands
            self.watchdog = CommandWatchdog(
                self.robot_model,
                joints,
                self.command_timeout,
                self.hw_gravity,
                float(param(self, 'hold_damping', 20.0)),
                float(param(self, 'hold_ramp', 0.05)),
            )
        # a floating base stays where it was placed until the first command (free running)
        self.base_hold = None
        self.base_release = float(param(self, 'base_release', 0.2))
        if not self.base_release >= 0.0:
            raise ValueError(f'base_release must be >= 0 s, got {self.base_release}')
        if self.floating and self.watchdog and bool(param(self, 'hold_base_until_command', True)):
            self.base_hold = self.server.hold_base(self.model)
        # start_paused: nothing moves until ~/unpause (e.g. once a recorder is listening)
        self.paused = bool(param(self, 'start_paused', False))
        self.commands = BridgeCommands(
            self.say, self.model, joints, self._cmd_map, self.robot_model, self._model_map,
            self._model_state, str(param(self, 'command_interface', 'effort')),
            float(param(self, 'servo_frequency', 20.0)), self.watchdog, self.hw_gravity,
            self.time_step, str(param(self, 'command_message', 'float64_multi_array')),
            (param(self, 'joint_stiffness', []) or None, param(self, 'joint_damping', []) or None),
        )
        self._last_cmd_time = None
        self._state_ns = 0  # the stamp of the state last published [ns]
        self.stale_answers = 0  # lockstep: commands dropped, answers to an instant already stepped
        self._resets = 0  # the simulator's resets of a blown-up state, told

        self.pub_js = self.create_publisher(JointState, 'joint_states', STATE_QOS)
        self.pub_odom = (
            self.create_publisher(Odometry, 'odom', STATE_QOS) if self.floating else None
        )
        self.pub_clock = self.create_publisher(Clock, '/clock', 10) if self.publish_clock else None
        command_topic = str(param(self, 'command_topic', '')) or f'/{controller_name}/commands'
        self.create_subscription(
            self.commands.wire.message_type, command_topic, self._on_command, COMMAND_QOS
        )
        self.create_service(Trigger, '~/reset', self._on_reset)
        # the controller's obstacle markers, as bodies in the simulation
        self.obstacles = SimObstacles(self, self.server, self.model)
        # pushes on the robot's links (~/external_force)
        self.push = SimPush(self, self.model, self.server.get_time)
        self.create_service(Trigger, '~/pause', self._on_pause)
        self.create_service(Trigger, '~/unpause', self._on_unpause)
        self._js = JointState()
        self._js.name = list(joints) + self.held
        if self.mode == 'free_running':
            self.steps_per_tick = max(1, int(round(1.0 / (self.rate * self.time_step))))
            self.create_timer(1.0 / self.rate, self._tick)
        else:
            self.steps_per_tick = max(1, int(round(self.control_period / self.time_step)))
            # until commands flow, keep announcing the state (late subscribers, restarts)
            self.create_timer(0.05, self._idle_publish)
        self.get_logger().info(
            f'{self.SIMULATOR} bridge: {len(joints)} joints, mode {self.mode}, '
            f'{self.steps_per_tick} step(s) of '
            f'{self.time_step * 1e3:.2f} ms per '
            f"{'command' if self.mode == 'lockstep' else 'tick'}, commands on "
            f'{command_topic}'
            f"{', hardware gravity compensation' if self.hw_gravity else ''}"
            f", model {'robot_description' if description_given else urdf}"
        )
        if self.base_hold is not None:
            self.get_logger().info('holding the base at its start until the first command')
        self._publish_state()

    # -------------------------------------------------------------- commands and stepping
    def _on_command(self, msg) -> None:
        if self.mode == 'lockstep' and self._answers_an_older_state(msg):
            self.stale_answers += 1
            return
        if not self.commands.take(msg, self.server.get_time()):
            if self.mode == 'lockstep':
                self._advance()  # the controller waits for a state: keep the loop alive
            return
        self._last_cmd_time = self.get_clock().now()
        if self.base_hold is not None:  # the first command: the base given way to it
            t = self.server.get_time()
            self.base_hold.release(t, self.base_release)
            self.base_hold = None
            at = ', '.join(f'{v:.6f}' for v in self.model.get_world_to_base_transform()[:3, 3])
            self.get_logger().info(
                f'first effort command at t = {t:.4f} s (simulated), the base at [{at}] m: '
                f'releasing it over {self.base_release:.3g} s'
            )
        if self.mode == 'lockstep':
            self._advance()

    def _answers_an_older_state(self, msg) -> bool:
        """
        Tell a command that answers a state older than the last published one.

        The instant it names (common.ANSWERS, or a JointState's stamp): the controller answers a
        state announced again (see the module) with the same command; sent twice, it must step
        once. Commands that name no state, or a later instant (a clock's stamp), step on arrival.
        """
        answered = self.commands.wire.answered(msg)
        return answered is not None and answered < self._state_ns

    def _advance(self) -> None:
        if self.stop_time > 0 and self.server.get_time() >= self.stop_time - 1e-9:
            self.paused = True
        if not self.paused:
            for k in range(self.steps_per_tick):
                self.commands.before_step(self.server.get_time(), k == 0)
                self.push.before_step()
                if self.hw_gravity:
                    self._update_gravity()
                self.server.step()
            if self.server.resets != self._resets:
                self._resets = self.server.resets
                self.say('error', 'simulation:reset',
                         f'the simulation blew up at t = {self.server.last_reset:.3f} s '
                         '(accelerations not finite: a torque far beyond what a joint takes in '
                         f"one step): {self.SIMULATOR} reset the robot to its model's rest pose")
        elif self.mode == 'lockstep':
            # paused: the idle announcements keep the controller informed (answering each command
            # with the same state would make the controller, which repeats its command for a
            # repeated state, ping-pong)
            return
        self._publish_state()

    def _model_state(self):
        """Copy the simulated state into the Pinocchio model; model-order q, v."""
        rm = self.robot_model
        q = self.model.get_joint_positions(self._model_map)
        v = self.model.get_joint_velocities(self._model_map)
        if self.floating:
            rm.set_robot_state(
                self.model.get_world_to_base_transform(),
                q,
                self.model.get_base_velocity(),
                v,
                self.model.get_gravity(),
            )
        else:
            rm.set_robot_state(q, v)
        return q, v

    def _update_gravity(self) -> None:
        self._model_state()
        self.model.set_joint_gravity_torques(
            self._model_map.to_sim(self.robot_model.get_joint_gravity_torques())
        )

    def _tick(self) -> None:
        self._advance()

    def _idle_publish(self) -> None:
        if (
            self._last_cmd_time is None
            or (self.get_clock().now() - self._last_cmd_time).nanoseconds > 2e8
        ):
            self._publish_state()

    def _publish_state(self) -> None:
        js = self._js
        if self.mode == 'lockstep':
            sec_to_stamp(self.server.get_time(), js.header.stamp)
        else:
            js.header.stamp = self.get_clock().now().to_msg()
        self._state_ns = stamp_ns(js.header.stamp)
        o = self._state_map
        js.position = self.model.get_joint_positions(o).tolist()
        v = self.model.get_joint_velocities(o).tolist() if self.publish_velocities else []
        js.velocity = v
        js.effort = self.model.get_joint_measured_torques(o).tolist()
        self.pub_js.publish(js)
        if self.pub_odom is not None:
            self.pub_odom.publish(odometry(self.model.get_world_to_base_transform(),
                                           self.model.get_base_velocity(), js.header.stamp,
                                           self.publish_odom_twist))
        if self.pub_clock is not None:
            c = Clock()
            sec_to_stamp(self.server.get_time(), c.clock)
            self.pub_clock.publish(c)

    # -------------------------------------------------------------- services
    def _on_reset(self, req, res):
        self.model.set_model_configuration(self.joints, self.initial)
        if self.held:
            self.model.set_model_configuration(self.held, self.held_positions)
        self.commands.reset()
        self.push.reset()
        self._publish_state()
        res.success, res.message = True, 'joints reset to initial_positions, command zeroed'
        return res

    def _on_pause(self, req, res):
        self.paused = True
        res.success, res.message = True, 'simulation paused'
        return res

    def _on_unpause(self, req, res):
        self.paused = False
        if self.stop_time > 0 and self.server.get_time() >= self.stop_time - 1e-9:
            self.stop_time = 0.0  # resumed at stop_time: it runs on past it
        if self.mode == 'lockstep':
            # one step with the last command starts the exchange again
            self._advance()
        res.success, res.message = True, 'simulation running'
        return res

    def destroy_node(self):
        self.server.shutdown()
        super().destroy_node()
