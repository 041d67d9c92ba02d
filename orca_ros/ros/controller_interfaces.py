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
The controller node's task targets, services and feedback (mixed into the node).

Per task ``<name>``: ``~/tasks/<name>/target_pose`` (geometry_msgs/PoseStamped; frame_id = any
model link, empty = the base frame) for Cartesian tasks, ``~/tasks/<name>/target``
(sensor_msgs/JointState) for joint tasks, ``~/tasks/<name>/set_active`` (std_srvs/SetBool, ramped),
and the feedback ``~/tasks/<name>/current_pose`` (PoseStamped) and ``~/tasks/<name>/error``
(Float64MultiArray: pose error [linear, angular] or joint error), and ``~/cycle_timing``
(Float64MultiArray, at the feedback rate: the cycles since the last message, as two rows of the
layout ``field`` x ``cycle``: controller time [s], then solve time [s]); ``~/markers`` at the
same rate (:mod:`.controller_markers`). Node services:
``~/activate`` / ``~/deactivate`` (Trigger: every task and constraint, ramped), ``~/enable``
(SetBool: false = hold with the safe command), ``~/reset_targets`` (Trigger: targets := current
state). ``/diagnostics`` (solver status, solve time, loop period and jitter, active tasks): the
part :mod:`.controller_diagnostics`, made here.
A pose target (``target_pose``, ``target_point``) outside the reach of the task's frame (a sphere
from the kinematic chain, :mod:`orca_ros.robot.reach`) is ignored with a WARN line naming the task
and the distance: the task holds its previous target.
"""

from __future__ import annotations

from geometry_msgs.msg import PoseStamped
import numpy as np
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, MultiArrayDimension
from std_srvs.srv import SetBool, Trigger
from trajectory_msgs.msg import MultiDOFJointTrajectoryPoint

from .common import DEFAULT_QOS, matrix_to_pose, pose_to_matrix
from .controller_diagnostics import ControllerDiagnostics
from ..robot.reach import task_reaches
from ..task import CartesianTask, CoMTask, JointAccelerationTask, JointTorqueTask


class ControllerInterfaces:
    def setup_interfaces(self, diagnostics_rate: float, feedback_rate: float) -> None:
        self._target_time: dict[str, float] = {}
        self._reach = task_reaches(self.robot, self.setup.tasks)  # once, at configuration
        self._feedback_pubs = {}
        for name, task in self.setup.tasks.items():
            base = f'~/tasks/{name}'
            if isinstance(task, CartesianTask):
                self.create_subscription(
                    PoseStamped,
                    f'{base}/target_pose',
                    lambda m, n=name: self._on_target_pose(n, m),
                    DEFAULT_QOS,
                )
                self.create_subscription(
                    MultiDOFJointTrajectoryPoint,
                    f'{base}/target_point',
                    lambda m, n=name: self._on_target_point(n, m),
                    DEFAULT_QOS,
                )
                pose_pub = self.create_publisher(PoseStamped, f'{base}/current_pose', DEFAULT_QOS)
            else:
                self.create_subscription(
                    JointState,
                    f'{base}/target',
                    lambda m, n=name: self._on_joint_target(n, m),
                    DEFAULT_QOS,
                )
                pose_pub = None
            err_pub = self.create_publisher(Float64MultiArray, f'{base}/error', DEFAULT_QOS)
            self._feedback_pubs[name] = (pose_pub, err_pub)
            self.create_service(
                SetBool,
                f'{base}/set_active',
                lambda rq, rs, n=name: self._on_set_active(n, rq, rs),
            )
        self.create_service(Trigger, '~/activate', self._on_activate)
        self.create_service(Trigger, '~/deactivate', self._on_deactivate)
        self.create_service(SetBool, '~/enable', self._on_enable)
        self.create_service(Trigger, '~/reset_targets', self._on_reset_targets)
        self.diagnostics = ControllerDiagnostics(self, diagnostics_rate)
        self._timing_pub = self.create_publisher(Float64MultiArray, '~/cycle_timing', DEFAULT_QOS)
        self._timing_sent = 0
        if feedback_rate > 0:
            self.create_timer(
                1.0 / feedback_rate, self.housekeeping.timer_callback(self._publish_feedback)
            )
        for name, active in self.setup.initially_active.items():
            obj = self.setup.tasks.get(name) or self.controller.get_constraint(name)
            if active:
                obj.activate()

    # -------------------------------------------------------------- targets
    def _on_target_pose(self, name: str, msg: PoseStamped) -> None:
        task = self.setup.tasks[name]
        frame = msg.header.frame_id
        try:
            T = pose_to_matrix(msg.pose)
            base = self.robot.get_base_frame()
            if frame and frame != base:
                if not self.robot.frame_exists(frame):
                    raise ValueError(
                        f"unknown frame '{frame}' (use 'world', '' for the base frame '{base}', "
                        'or a link of the model)'
                    )
                if not self.have_state:
                    raise ValueError(f"frame '{frame}' needs a joint state to be resolved")
                self.apply_state()
                T = self.robot.get_relative_transform(base, frame) @ T
            elif self.have_state:
                self.apply_state()
            if self._out_of_reach(name, T):
                return
            if not self._smooth(name, T):
                task.servo_controller().set_desired(T)
        except ValueError as exc:
            self.say('error', f'target:{name}', f"target for task '{name}' rejected: {exc}")
            return
        self._target_time[name] = self.now()

    def _on_target_point(self, name: str, msg: MultiDOFJointTrajectoryPoint) -> None:
        """Pose, twist and acceleration (feed-forward) of a Cartesian task, in the base frame."""
        task = self.setup.tasks[name]
        try:
            if len(msg.transforms) != 1:
                raise ValueError('target_point needs exactly one transform')
            tr = msg.transforms[0]
            T = np.eye(4)
            T[:3, 3] = (tr.translation.x, tr.translation.y, tr.translation.z)
            q = tr.rotation
            T[:3, :3] = pose_to_matrix(_quat_pose(q))[:3, :3]
            vel, acc = np.zeros(6), np.zeros(6)
            for src, out in ((msg.velocities, vel), (msg.accelerations, acc)):
                if len(src) > 1:
                    raise ValueError('at most one velocity and one acceleration')
                if len(src) == 1:
                    out[:] = (
                        src[0].linear.x,
                        src[0].linear.y,
                        src[0].linear.z,
                        src[0].angular.x,
                        src[0].angular.y,
                        src[0].angular.z,
                    )
            if not (
                np.all(np.isfinite(T)) and np.all(np.isfinite(vel)) and np.all(np.isfinite(acc))
            ):
                raise ValueError('NaN or infinite values')
            if self._out_of_reach(name, T):
                return
            self.targets.stop(name)  # a trajectory point already: as it is
            task.servo_controller().set_desired(T, vel, acc)
        except ValueError as exc:
            self.say('error', f'target:{name}', f"target point for task '{name}' rejected: {exc}")
            return
        self._target_time[name] = self.now()

    def _out_of_reach(self, name: str, T) -> bool:
        """Whether a pose target (base frame) is out of the task's reach: WARN, target ignored."""
        reach = self._reach.get(name)
        why = None if reach is None else reach.refusal(name, T[:3, 3])
        if why is not None:
            self.say('warning', f'reach:{name}', why)
        return why is not None

    def _on_joint_target(self, name: str, msg: JointState) -> None:
        task = self.setup.tasks[name]
        try:
            names = list(msg.name)
            missing = [j for j in self.setup.joints if j not in names]
            if missing:
                raise ValueError(f'missing joints {missing}')
            idx = [names.index(j) for j in self.setup.joints]
            model = self._wire_of_model

            def pick(arr):
                if len(arr) == 0:
                    return None
                if len(arr) != len(names):
                    raise ValueError('array sizes do not match the joint names')
                return np.asarray(arr, dtype=float)[idx][model]

            pos, vel, eff = pick(msg.position), pick(msg.velocity), pick(msg.effort)
            if isinstance(task, JointTorqueTask):
                if eff is None:
                    raise ValueError("a torque task needs 'effort' values")
                task.set_desired(eff)
            else:
                if pos is None:
                    raise ValueError("a joint task needs 'position' values")
                if not np.isfinite(pos).all() or (vel is not None and not np.isfinite(vel).all()):
                    raise ValueError('NaN or infinite values')
                if vel is not None or not self._smooth(name, pos):
                    self.targets.stop(name)
                    task.set_desired(pos, vel)
        except ValueError as exc:
            self.say('error', f'target:{name}', f"target for task '{name}' rejected: {exc}")
            return
        self._target_time[name] = self.now()

    def _smooth(self, name: str, target) -> bool:
        """Start a trajectory to ``target`` once the robot was seen (TargetSmoothing.smooth)."""
        return self.have_state and self.targets.smooth(name, target, self.now(), self._q,
                                                       self._v)

    def expire_targets(self, t: float) -> None:
        if self.target_timeout <= 0:
            return
        for name, stamp in list(self._target_time.items()):
            if t - stamp > self.target_timeout:
                self.get_logger().warning(
                    f"target of task '{name}' older than {self.target_timeout} s: "
                    'holding the current state'
                )
                self.hold_task(self.setup.tasks[name])
                del self._target_time[name]

    def hold_task(self, task) -> None:
        """
        Target := the current state (zero velocity), integrators cleared.

        The task stops pulling.
        """
        self.targets.stop(task.name)
        if isinstance(task, CartesianTask):
            task.servo_controller().hold_current_pose()
            task.servo_controller().pid().reset()
        elif isinstance(task, JointAccelerationTask):
            task.hold_current_position()
            task.pid().reset()
        elif isinstance(task, CoMTask):
            task.set_desired(task.get_current_position())
            task.pid().reset()

    # -------------------------------------------------------------- services
    def _on_set_active(self, name, req, res):
        task = self.setup.tasks[name]
        if not req.data and self.have_state and task.is_computing():
            self.apply_state()
            self.hold_task(task)  # ramping out where it is, not pulling towards its old target
        changed = task.activate() if req.data else task.deactivate()
        res.success = True
        res.message = (
            f"task '{name}' {'activating' if req.data else 'deactivating'}"
            if changed
            else f"task '{name}' already {task.get_state().value}"
        )
        return res

    def _on_activate(self, req, res):
        self.controller.activate_tasks_and_constraints()
        res.success, res.message = True, 'activating every task and constraint'
        return res

    def _on_deactivate(self, req, res):
        # stop where you are: every target latches to the current state before the ramps start, so
        # nothing pulls while the tasks fade out; what remains is gravity compensation at rest
        if self.have_state:
            self._reset_targets()
        self.controller.deactivate_tasks_and_constraints()
        res.success, res.message = (
            True,
            'deactivating every task and constraint (targets latched to the current state)',
        )
        return res

    def _on_enable(self, req, res):
        if req.data and not self.enabled and self.have_state:
            self._reset_targets()  # resume from where the robot is, not from old targets
        self.enabled = bool(req.data)
        res.success = True
        res.message = 'control enabled' if req.data else 'holding (gravity + damping)'
        return res

    def _on_reset_targets(self, req, res):
        if not self.have_state:
            res.success, res.message = False, 'no joint state received yet'
            return res
        self._reset_targets()
        res.success, res.message = True, 'targets set to the current state'
        return res

    def _reset_targets(self) -> None:
        self.apply_state()
        for task in self.setup.tasks.values():
            self.hold_task(task)
        self._target_time.clear()

    # -------------------------------------------------------------- feedback and diagnostics
    def _publish_feedback(self):
        """
        Publish each task's pose and error, the cycles' timing and the markers.

        A job (housekeeping.py): one slice per task, each stamped when it runs.
        """
        if not self.have_state:
            return
        for name, task in self.setup.tasks.items():
            pose_pub, err_pub = self._feedback_pubs[name]
            err = Float64MultiArray()
            if isinstance(task, CartesianTask):
                servo = task.servo_controller()
                msg = PoseStamped()
                msg.header.stamp = self.get_clock().now().to_msg()
                msg.header.frame_id = self.robot.get_base_frame()
                matrix_to_pose(servo.get_current_cartesian_pose(), msg.pose)
                pose_pub.publish(msg)
                e = servo.get_cartesian_pose_error()
                self.diagnostics.error_watch.observe(
                    name, float(np.linalg.norm(e[:3])) if task.is_computing() else 0.0, self.now()
                )
                err.data = e.tolist()
            elif isinstance(task, JointAccelerationTask):
                err.data = task.get_position_error().tolist()
            err_pub.publish(err)
            yield
        self._publish_cycle_timing()
        yield
        if self.have_state:
            self.markers.publish()

    def _publish_cycle_timing(self) -> None:
        total = self.stats.solve_times.total
        k = min(total - self._timing_sent, self.stats.solve_times.capacity)
        self._timing_sent = total
        if k <= 0:
            return
        msg = Float64MultiArray()
        msg.layout.dim = [
            MultiArrayDimension(label='field', size=2, stride=2 * k),
            MultiArrayDimension(label='cycle', size=k, stride=k),
        ]
        msg.data = np.concatenate(
            (self.stats.cycle_stamps.latest(k), self.stats.solve_times.latest(k))
        ).tolist()
        self._timing_pub.publish(msg)


def _quat_pose(q):
    """Make a geometry_msgs Pose with orientation q (for pose_to_matrix's quaternion checks)."""
    from geometry_msgs.msg import Pose  # noqa: PLC0415

    p = Pose()
    p.orientation = q
    return p
