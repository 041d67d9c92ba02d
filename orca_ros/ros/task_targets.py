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
The controller node's task targets: one input per task, checked, smoothed, held and expired.

A part of :class:`.controller_node.OrcaControllerNode`. Per task ``<name>``:
``~/tasks/<name>/target_pose`` (geometry_msgs/PoseStamped; frame_id = any model link, empty =
the base frame) and ``~/tasks/<name>/target_point`` (trajectory_msgs/MultiDOFJointTrajectoryPoint:
pose, twist and acceleration in the base frame) for Cartesian tasks, ``~/tasks/<name>/target``
(sensor_msgs/JointState, by joint name; efforts for a torque task) for joint tasks. A bad target
(unknown frame, NaN, missing joints, wrong sizes) is refused with an ERROR line naming the task
and the cause; the task keeps its previous target. A pose target outside the reach of the task's
frame (a sphere from the kinematic chain, :mod:`orca_ros.robot.reach`) is ignored with a WARN
line naming the task and the distance. Targets without velocities become trajectories
(:class:`.target_smoothing.TargetSmoothing`, the part's ``smoothing``). ``target_timeout`` > 0:
a task whose last target is older is held where it is (:meth:`TaskTargets.hold`).
"""

from __future__ import annotations

from geometry_msgs.msg import Pose, PoseStamped
import numpy as np
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import MultiDOFJointTrajectoryPoint

from .common import DEFAULT_QOS, pose_to_matrix
from ..robot.reach import task_reaches
from ..task import CartesianTask, CoMTask, JointAccelerationTask, JointTorqueTask


class TaskTargets:
    """
    The tasks' target inputs (see the module).

    ``node``: where the subscriptions live, its throttled log (``say``), its time (``now()``)
    and whether the robot was seen (``have_state``); ``state``: the node's
    :class:`.measured_state.MeasuredState`; ``smoothing``: the tasks' trajectories;
    ``timeout`` [s]: the target expiry (0: none; a live parameter).
    """

    def __init__(self, node, setup, robot, state, smoothing, timeout: float):
        self.node, self.setup, self.robot, self.state = node, setup, robot, state
        self.smoothing = smoothing
        self.timeout = timeout
        self._time: dict[str, float] = {}  # when each task's target last came
        self._reach = task_reaches(robot, setup.tasks)  # once, at configuration
        for name, task in setup.tasks.items():
            base = f'~/tasks/{name}'
            if isinstance(task, CartesianTask):
                node.create_subscription(PoseStamped, f'{base}/target_pose',
                                         lambda m, n=name: self._on_pose(n, m), DEFAULT_QOS)
                node.create_subscription(MultiDOFJointTrajectoryPoint, f'{base}/target_point',
                                         lambda m, n=name: self._on_point(n, m), DEFAULT_QOS)
            else:
                node.create_subscription(JointState, f'{base}/target',
                                         lambda m, n=name: self._on_joints(n, m), DEFAULT_QOS)

    def _taken(self, name: str, why: str | None, what: str = 'target') -> None:
        """Record when task ``name``'s target came, or say why it was refused (``why``)."""
        if why is None:
            self._time[name] = self.node.now()
        else:
            self.node.say('error', f'target:{name}', f"{what} for task '{name}' rejected: {why}")

    def _on_pose(self, name: str, msg: PoseStamped) -> None:
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
                if not self.node.have_state:
                    raise ValueError(f"frame '{frame}' needs a joint state to be resolved")
                self.state.apply()
                T = self.robot.get_relative_transform(base, frame) @ T
            elif self.node.have_state:
                self.state.apply()
            if self._out_of_reach(name, T):
                return
            if not self._smooth(name, T):
                self.setup.tasks[name].servo_controller().set_desired(T)
        except ValueError as exc:
            return self._taken(name, str(exc))
        self._taken(name, None)

    def _on_point(self, name: str, msg: MultiDOFJointTrajectoryPoint) -> None:
        """Pose, twist and acceleration (feed-forward) of a Cartesian task, in the base frame."""
        try:
            if len(msg.transforms) != 1:
                raise ValueError('target_point needs exactly one transform')
            tr = msg.transforms[0]
            T = pose_to_matrix(Pose(orientation=tr.rotation))
            T[:3, 3] = (tr.translation.x, tr.translation.y, tr.translation.z)
            vel, acc = np.zeros(6), np.zeros(6)
            for src, out in ((msg.velocities, vel), (msg.accelerations, acc)):
                if len(src) > 1:
                    raise ValueError('at most one velocity and one acceleration')
                if len(src) == 1:
                    lin, ang = src[0].linear, src[0].angular
                    out[:] = (lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
            if not (np.isfinite(T).all() and np.isfinite(vel).all() and np.isfinite(acc).all()):
                raise ValueError('NaN or infinite values')
            if self._out_of_reach(name, T):
                return
            self.smoothing.stop(name)  # a trajectory point already: as it is
            self.setup.tasks[name].servo_controller().set_desired(T, vel, acc)
        except ValueError as exc:
            return self._taken(name, str(exc), 'target point')
        self._taken(name, None)

    def _out_of_reach(self, name: str, T) -> bool:
        """Whether a pose target (base frame) is out of the task's reach: WARN, target ignored."""
        reach = self._reach.get(name)
        why = None if reach is None else reach.refusal(name, T[:3, 3])
        if why is not None:
            self.node.say('warning', f'reach:{name}', why)
        return why is not None

    def _on_joints(self, name: str, msg: JointState) -> None:
        task = self.setup.tasks[name]
        try:
            names = list(msg.name)
            missing = [j for j in self.setup.joints if j not in names]
            if missing:
                raise ValueError(f'missing joints {missing}')
            idx = [names.index(j) for j in self.setup.joints]
            model = self.setup.model_index  # model joint k -> wire slot

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
                    self.smoothing.stop(name)
                    task.set_desired(pos, vel)
        except ValueError as exc:
            return self._taken(name, str(exc))
        self._taken(name, None)

    def _smooth(self, name: str, target) -> bool:
        """Start a trajectory to ``target`` once the robot was seen (TargetSmoothing.smooth)."""
        return self.node.have_state and self.smoothing.smooth(
            name, target, self.node.now(), self.state.q, self.state.v
        )

    def expire(self, t: float) -> None:
        """Hold each task whose last target is older than ``timeout`` at ``t`` (said once)."""
        if self.timeout <= 0:
            return
        for name, stamp in list(self._time.items()):
            if t - stamp > self.timeout:
                self.node.say('warning', f'expired:{name}',
                              f"target of task '{name}' older than {self.timeout} s: "
                              'holding the current state')
                self.hold(self.setup.tasks[name])
                del self._time[name]

    def hold(self, task) -> None:
        """
        Target := the current state (zero velocity), integrators cleared.

        The task stops pulling. The model must hold the measured state.
        """
        self.smoothing.stop(task.name)
        if isinstance(task, CartesianTask):
            task.servo_controller().hold_current_pose()
            task.servo_controller().pid().reset()
        elif isinstance(task, JointAccelerationTask):
            task.hold_current_position()
            task.pid().reset()
        elif isinstance(task, CoMTask):
            task.set_desired(task.get_current_position())
            task.pid().reset()

    def hold_all(self) -> None:
        """Every task's target := the measured state (needs one); no target expires."""
        self.state.apply()
        for task in self.setup.tasks.values():
            self.hold(task)
        self._time.clear()

    def set_active(self, task, active: bool) -> bool:
        """
        Ramp ``task`` in or out; return whether its state changed.

        Out: held where the robot is first (it fades out in place, not pulling towards its old
        target).
        """
        if active:
            return task.activate()
        if self.node.have_state and task.is_computing():
            self.state.apply()
            self.hold(task)
        return task.deactivate()
