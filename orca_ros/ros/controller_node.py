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
orca_controller: the whole-body controller as a ROS 2 node.

In: ``joint_states`` (mapped by name, extra joints ignored, best effort, depth 1). Out: effort
commands on ``command_topic`` (Float64MultiArray in the ``joints`` order, reliable). Joints of the
URDF that ``joints`` leaves out are locked in the model at the positions the joint states report
(another controller drives them) and never commanded. The QP runs in
a fixed-rate timer (``trigger: timer``) or once per received state (``trigger: joint_state``, for
lockstep simulation). Task targets, services, feedback and diagnostics: the parts
:mod:`.task_targets`, :mod:`.activation_services`, :mod:`.task_feedback` and
:mod:`.controller_diagnostics`.

Safety: nothing is published before the first valid joint state; NaN/incomplete states are
rejected; a stale state, a QP failure, ``~/enable false`` or shutdown switch to the safe command
(last command fading into gravity + damping, see :class:`orca_ros.safety.SafeCommand`), with a log
line saying why; normal control resumes when good data returns.
"""

from __future__ import annotations

import sys
import time

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from .activation_services import ActivationServices
from .command_output import CommandOutput
from .common import nested_parameters, param, run_node, stamp_ns, stamp_to_sec, STATE_QOS
from .common import wait_for_robot_description
from .controller_diagnostics import ControllerDiagnostics
from .controller_markers import ControllerMarkers
from .guarded_node import GuardedNode
from .housekeeping import GarbageCollection, Housekeeping
from .live_parameters import LiveParameters
from .loop_statistics import LoopStatistics
from .measured_state import MeasuredState, StateRejected
from .obstacle_markers import ObstacleInput
from .realtime import configure_scheduling
from .target_smoothing import TargetSmoothing
from .task_feedback import TaskFeedback
from .task_targets import TaskTargets
from ..configuration import build_from_config
from ..safety import SafeCommand


class OrcaControllerNode(GuardedNode):
    """
    The controller node: the loop and its lockstep decisions; the rest are parts.

    Parts: ``state`` (:class:`.measured_state.MeasuredState`), ``output``
    (:class:`.command_output.CommandOutput`), ``targets`` (:class:`.task_targets.TaskTargets`),
    ``activation`` (:class:`.activation_services.ActivationServices`), ``feedback``
    (:class:`.task_feedback.TaskFeedback`), ``diagnostics``, ``markers``, ``obstacles``,
    ``live_parameters``, ``stats``, ``housekeeping``.
    """

    def __init__(self, **kwargs):
        super().__init__(
            'orca_controller', automatically_declare_parameters_from_overrides=True, **kwargs
        )
        cfg = {
            k: param(self, k, d)
            for k, d in (
                ('urdf_path', ''), ('robot_description', ''), ('base_frame', ''), ('joints', []),
                ('solver', 'daqp'), ('resolution_strategy', 'one_level_weighted'),
                ('floating_base', False), ('gravity_compensated_by_hardware', False),
                ('compiled', True), ('locked_joint_tolerance', 1e-4), ('kinematic', False),
            )
        }
        if not cfg['urdf_path'] and not cfg['robot_description']:
            cfg['robot_description'] = wait_for_robot_description(
                self, float(param(self, 'robot_description_timeout', 60.0))
            )
        cfg['tasks'] = nested_parameters(self, 'tasks')
        self.floating = bool(cfg['floating_base'])
        cfg['constraints'] = nested_parameters(self, 'constraints')
        self.setup = setup = build_from_config(cfg)
        self.robot, self.controller = setup.robot, setup.controller
        if self.controller.solver_fallback:
            self.get_logger().warning(self.controller.solver_fallback)
        # configure now: the compiled cycle's kernels compile (or load from their disk cache)
        # here, not in the first control cycle
        self.controller.get_levels()
        cycle = self.controller.compiled_cycle
        self.get_logger().info(
            cycle.describe() if cycle is not None else 'reference path (compiled: false)'
        )
        self.n = len(setup.joints)
        self.update_rate = float(param(self, 'update_rate', 1000.0))
        self.period = 1.0 / self.update_rate
        self.trigger = str(param(self, 'trigger', 'timer'))
        self.state_timeout = float(param(self, 'state_timeout', 0.05))
        self.solver_budget = [
            float(param(self, 'solver_time_budget', 0.0)),
            int(param(self, 'solver_max_iterations', 0)),
        ]
        self.set_solver_budget(*self.solver_budget)
        self.safe = SafeCommand(
            self.robot,
            setup.gravity_compensated_by_hardware,
            float(param(self, 'safe_damping', 10.0)),
            float(param(self, 'safe_ramp', 0.2)),
        )
        # the node sends this one on every fault (stale states and holds too): the core's own,
        # after a failed update, would be computed for nothing
        setup.controller.safe_command = None
        self.state = MeasuredState(
            self.robot, setup.joints, setup.model_index, floating=self.floating,
            lockstep=self.trigger == 'joint_state',
            position_margin=float(param(self, 'position_margin', 0.1)),
            velocity_factor=float(param(self, 'velocity_factor', 3.0)),
            odom_twist=str(param(self, 'odom_twist', 'auto')),
            gravity=param(self, 'gravity', [0.0, 0.0, -9.81]), say=self.say,
        )
        self._stopped = False
        self._computed_stamp = None  # lockstep: the instant the last cycle computed
        self.have_state = False
        self._t_prev = None
        self._diagnosed = False
        # the loop's counters and its statistics over a bounded window
        self.stats = LoopStatistics(int(param(self, 'statistics_window', 10000)))
        # garbage collection out of the control cycle: frozen before the first command
        self.collector = GarbageCollection(bool(param(self, 'manage_gc', True)))
        # real-time scheduling of the node's process (see realtime.py), as ros2_control's
        self.thread_priority = int(param(self, 'thread_priority', 50))
        self.cpu_affinity = [int(c) for c in param(self, 'cpu_affinity', [])]
        self.scheduling_refused = ''  # why the request above was not met (for /diagnostics)
        self._last_loop_wall = None
        # feedback, diagnostics and garbage collection run in the slack after a cycle's command
        self.housekeeping = Housekeeping(
            self.period, lambda name, exc: self.say_raised(f"timer '{name}'", exc)
        )
        self.output = CommandOutput.of_node(self, self.robot, self.safe, setup.model_index,
                                            self.trigger == 'joint_state', setup.joints)
        self.create_subscription(JointState, 'joint_states', self._on_joint_state, STATE_QOS)
        if self.floating:  # the base pose and twist (twist in child_frame_id)
            self.create_subscription(
                Odometry, str(param(self, 'odom_topic', 'odom')), self._on_odom, STATE_QOS
            )
        self.targets = TaskTargets(
            self, setup, self.robot, self.state,
            TargetSmoothing(setup, self.robot, cfg['tasks'], self.say),
            float(param(self, 'target_timeout', 0.0)),
        )
        self.obstacles = ObstacleInput(self, self.controller, self.robot,
                                       self.trigger == 'joint_state')
        self.markers = ControllerMarkers(self, self.robot, self.controller.layout.contacts,
                                         self.floating, self.state_time)
        self.activation = ActivationServices(self, setup, self.controller, self.targets)
        self.diagnostics = ControllerDiagnostics(self, float(param(self, 'diagnostics_rate', 5.0)))
        self.feedback = TaskFeedback(
            self, setup, self.robot, self.stats, self.diagnostics.error_watch, self.markers,
            float(param(self, 'feedback_rate', 50.0)), self.housekeeping,
        )
        if self.collector.managed:
            self.create_timer(float(param(self, 'gc_period', 1.0)),
                              self.housekeeping.timer_callback(self.collector.collect_garbage))
        if self.trigger == 'timer':
            self.create_timer(self.period, self._control_step)
        elif self.trigger != 'joint_state':
            raise ValueError(f"trigger must be 'timer' or 'joint_state', got '{self.trigger}'")
        self.live_parameters = LiveParameters(self)
        self.get_logger().info(
            f'orca_controller: {self.n} joints'
            f"{f' (locked: {self.state.locked})' if self.state.locked else ''}, "
            f'{self.update_rate:.0f} Hz ({self.trigger}), solver '
            f'{self.controller.solver.value}, tasks {list(setup.tasks)}, model '
            f"{self.robot.mjcf_path or self.robot.urdf_path or 'robot_description'}"
        )

    def set_solver_budget(self, time_budget: float, max_iterations: int) -> None:
        """
        Set the solve budget of every cycle.

        0 s: one control period with a timer (the cycle must end in time), 1 s in lockstep (the
        simulation waits for the command: a busy machine must not change the outcome); 0
        iterations: the solver's cap.
        """
        if time_budget <= 0.0:
            time_budget = None if self.trigger == 'timer' else 1.0
        self.controller.set_solver_budget(
            time_budget, max_iterations if max_iterations > 0 else None
        )

    # -------------------------------------------------------------- state input
    def _on_joint_state(self, msg: JointState) -> None:
        """
        Take a joint state; compute a cycle when a lockstep instant is complete.

        Lockstep (``trigger: joint_state``): a state repeated with the same stamp (the simulator
        re-announcing an instant no command reached) re-sends the command of that instant
        instead of computing another step; a rejected state of a new instant is answered with
        the hold (the simulator steps only once an instant is answered).
        """
        stamp = stamp_to_sec(msg.header.stamp)
        try:
            new = self.state.read_joint_state(msg)
        except StateRejected as exc:
            self.say('error', exc.cause, str(exc))
            if (self.trigger == 'joint_state' and self.have_state and not self._stopped
                    and stamp > self.state.stamp):
                self.output.answered = stamp_ns(msg.header.stamp)
                self._publish_safe(self.now(), 'safe:state', f'joint state rejected ({exc})',
                                   fresh=False)
            return
        if new:
            self.output.answered = stamp_ns(msg.header.stamp)
            self._on_new_state()
        elif not self._stopped:
            if stamp == self._computed_stamp:
                self.output.repeat()
            elif stamp == self.state.stamp:  # not answered yet (the cycle that froze the
                self._on_new_state()  # collector sends nothing): answered now

    def _on_odom(self, msg: Odometry) -> None:
        if self.state.read_odom(msg):
            self._on_new_state()

    def _on_new_state(self) -> None:
        if not self.state.ready:
            return
        if not self.have_state:
            self.have_state = True
            self.state.apply()
            self.get_logger().info('first joint state received: control starts')
            # far targets along trajectories, not as steps
            self.targets.smoothing.start_configured(self.now(), self.state.q, self.state.v)
        if self.trigger == 'joint_state':
            # lockstep: one step per simulated instant, once joint state (and odom) of it are in
            if not self.state.instant_complete or self._computed_stamp == self.state.stamp:
                return
            self._computed_stamp = self.state.stamp
            self._control_step()

    # -------------------------------------------------------------- control
    def state_time(self) -> Time:
        """Return the stamp of the state the model holds: in lockstep its simulated instant."""
        if self.trigger == 'joint_state' and self._computed_stamp is not None:
            ns = int(round(self._computed_stamp * 1e9))
            return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        return self.get_clock().now().to_msg()

    def now(self) -> float:
        """Return the controller's time [s]: the states' stamps in lockstep, else monotonic."""
        # lockstep runs follow the simulated time stamped on the states (deterministic); others the
        # wall clock
        if self.trigger == 'joint_state' and self.state.stamp is not None:
            return self.state.stamp
        return time.monotonic()

    def _control_step(self) -> None:
        self._cycle()
        self.housekeeping.after_cycle()

    def _cycle(self) -> None:
        if not self.have_state or self._stopped:
            return  # nothing is sent before the first valid state, nor after the shutdown hold
        if self.collector.due:
            # before the first command, where its pause holds up none; the state it aged is not
            # answered: the next cycle's is fresh
            self.collector.freeze()
            self._computed_stamp = None  # unanswered: a repeated state is computed, not repeated
            return
        self.stats.loop_cycles += 1
        wall = time.monotonic()
        if self._last_loop_wall is not None:
            self.stats.loop_periods.push(wall - self._last_loop_wall)
        self._last_loop_wall = wall
        t = self.now()
        dt = self.period if self._t_prev is None else max(1e-6, t - self._t_prev)
        self._t_prev = t
        stale = None
        # lockstep: a step runs only once the state of a new instant is in (the simulator waits),
        # so the wall-clock time between joint states and odom of one instant (long on a busy
        # machine) is no staleness; a silent simulator shows in the diagnostics instead
        if self.trigger == 'timer':
            if wall - self.state.wall > self.state_timeout:
                stale = 'joint_states'
            elif self.floating and wall - self.state.odom_wall > self.state_timeout:
                stale = 'odom'
        if stale is not None:
            self._publish_safe(
                t,
                'safe:stale',
                f'{stale} stale (none valid for more than {self.state_timeout * 1e3:.0f} ms)',
                fresh=False,
            )
            return
        # the state the cycle runs on: the measured one, or the reference position and velocity
        # drives follow (orca_ros.command.JointCommand.state)
        self.state.apply(*self.output.command.state(self.state.q, self.state.v))
        if not self.activation.enabled:
            self._publish_safe(
                t, 'safe:disabled', 'controller disabled (~/enable false)', level='info'
            )
            return
        self.targets.expire(t)
        self.targets.smoothing.advance(t, self.state.q)
        t0 = time.perf_counter()
        try:
            ok = self.controller.update(t, dt)
        except Exception as exc:  # a bug or bad data must not kill the node: go safe and say why
            self.say('error', 'update', f'controller update raised {type(exc).__name__}: {exc}')
            ok = False
        self.stats.solve_times.push(time.perf_counter() - t0)
        self.stats.cycle_stamps.push(t)
        if not ok:
            code = self.controller.get_return_code()
            self.stats.qp_failures += 1
            self.stats.last_qp_failure = f'no QP solution ({code.value})'
            self._publish_safe(t, 'safe:qp', self.stats.last_qp_failure)
            if not self._diagnosed:  # once per failing spell, after the safe command went out
                self._diagnosed = True
                self.diagnostics.diagnose_failure()
            return
        if self.controller.contacts_relaxed():
            self.stats.contacts_relaxed_cycles += 1
            self.say('warning', 'contacts', 'rigid contacts infeasible: solved with the contacts '
                     'allowed to slip (elastic existence conditions)')
        if not self.output.solved(
            self.state.q, self.state.v, self.controller.get_joint_torque_command(),
            self.controller.get_joint_acceleration_command(), dt,
        ):
            self._publish_safe(t, 'safe:nonfinite', 'non-finite torque or acceleration command')
            return
        reason = self.output.recovered()
        if reason is not None:
            self.say('info', 'recovered', f'recovered from: {reason}')
            self._diagnosed = False
        self.stats.latencies.push(time.monotonic() - self.state.wall)

    def _publish_safe(
        self, t: float, cause: str, reason: str, fresh: bool = True, level: str = 'warning'
    ) -> None:
        """Send the hold at the measured state (``fresh`` False: stale, on the wall clock)."""
        self.output.hold(
            t if fresh else time.monotonic(), cause, reason, self.state.q, self.state.v, fresh,
            level,
        )

    def shutdown_command(self) -> None:
        """
        On SIGINT / SIGTERM / shutdown, while the context is valid.

        Stop the loop and send the hold (gravity at the last state, zero when the drives compensate
        it), waiting until it is delivered.
        """
        self._stopped = True
        if not self.have_state:
            return
        delivered = self.output.shutdown_hold(self.state.q)
        self.get_logger().info(
            'shutdown: hold command sent' + ('' if delivered else ' (delivery not confirmed)')
        )

    def on_callback_error(self, what: str, exc: Exception) -> None:
        """
        React to a raising callback.

        If control is running, this cycle sends the safe command.
        """
        if self.have_state and not self._stopped and 'control_step' in what:
            self._publish_safe(self.now(), 'safe:error', f'{what} raised {type(exc).__name__}')

    def configure_process(self) -> None:
        """Apply ``thread_priority`` and ``cpu_affinity`` to the process (run_node calls it)."""
        refused = []
        for level, text in configure_scheduling(self.thread_priority, self.cpu_affinity):
            getattr(self.get_logger(), level)(text)
            if level != 'info':
                refused.append(text)
        self.scheduling_refused = '; '.join(refused)


def main(args=None) -> int:
    return run_node(OrcaControllerNode, args, on_shutdown='shutdown_command')


if __name__ == '__main__':
    sys.exit(main())
