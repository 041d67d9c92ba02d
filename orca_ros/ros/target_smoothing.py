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
New targets become jerk-limited trajectories (a part of the controller node).

Per task, parameters under ``tasks.<name>.trajectory``: ``enabled`` [true]; Cartesian tasks
``max_velocity`` [0.25 m/s, 1.0 rad/s], ``max_acceleration`` [1.0 m/s^2, 3.0 rad/s^2], ``max_jerk``
[5 m/s^3, 15 rad/s^3] ([linear, angular]); joint tasks ``max_velocity`` [half the URDF velocity
limits], ``max_acceleration`` [2 rad/s^2], ``max_jerk`` [20 rad/s^3] (one value or one per joint).
A target on ``target_pose`` or a joint ``target`` without velocities starts a trajectory from the
current reference (or, when none runs or the servo does not follow it, from the measured state);
``target_point`` and joint targets with velocities are trajectory points already and go to the
servo as they are. Holding, resetting or expiring a target stops the trajectory. ``max_lead``
[0.2 s]: the reference never leads the measured state by more than it covers in this time at
``max_velocity``; beyond, it restarts on that leash (see :mod:`orca_ros.servo.target_trajectory`),
and the log says so (WARN, at most once a second per task).

Configured targets (``target_position`` of a Cartesian task, ``target`` of a joint task) are set
before the robot is seen. At the first state (:meth:`TargetSmoothing.start_configured`),
one the robot is far from (beyond half the lead bound, where a running trajectory counts as not
followed) becomes a trajectory from the measured
state instead of a step (a step of d asks kp d of acceleration at once, beyond what contacts and
torques give for a lying robot's trunk), said once (WARN). Nearer, it stays a step, as before.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..servo.target_trajectory import CartesianTrajectory, JointTrajectory, MAX_LEAD
from ..task import CartesianTask, JointAccelerationTask

CARTESIAN_DEFAULTS = {
    'max_velocity': [0.25, 1.0],
    'max_acceleration': [1.0, 3.0],
    'max_jerk': [5.0, 15.0],
    'max_lead': MAX_LEAD,
}


class TargetSmoothing:
    """
    The controller node's target trajectories: a part of the node (see the module).

    ``setup``: the configured controller (its tasks by name); ``task_config``: the tasks'
    parameters; ``say``: the node's throttled log. The measured joint state (model order) and
    the controller's time are arguments of each call.
    """

    def __init__(self, setup, robot, task_config: dict, say):
        self.setup, self.say = setup, say
        self.n = len(setup.joints)
        self.trajectories: dict = {}
        self.running: set[str] = set()
        # tasks whose configuration gives a target (start_configured)
        self.configured = [
            name for name, task in setup.tasks.items()
            if ('target_position' if isinstance(task, CartesianTask) else 'target')
            in (task_config.get(name) or {})
        ]
        for name, task in setup.tasks.items():
            cfg = dict((task_config.get(name) or {}).get('trajectory') or {})
            if not cfg.pop('enabled', True):
                continue
            if isinstance(task, CartesianTask):
                lim = {k: cfg.get(k, d) for k, d in CARTESIAN_DEFAULTS.items()}
                self.trajectories[name] = CartesianTrajectory(**lim)
            elif isinstance(task, JointAccelerationTask):
                vel = robot.get_joint_velocity_limits()
                vel = np.where(np.isfinite(vel) & (vel > 0), 0.5 * vel, 1.0)
                self.trajectories[name] = JointTrajectory(
                    self.n,
                    cfg.get('max_velocity', vel),
                    cfg.get('max_acceleration', 2.0),
                    cfg.get('max_jerk', 20.0),
                    cfg.get('max_lead', MAX_LEAD),
                )

    def smooth(self, name: str, target, t: float, q, v) -> bool:
        """
        Start a trajectory to ``target`` (4x4 pose in the base frame, or joint positions) at t.

        False when this task takes targets as steps. Starts from the running reference if the
        servo follows it, else from the measured state (``q``, ``v``: the joints').
        """
        gen = self.trajectories.get(name)
        if gen is None:
            return False
        if isinstance(gen, CartesianTrajectory):
            servo = self.setup.tasks[name].servo_controller()
            pose = servo.get_current_cartesian_pose()
            measured = pose, servo.get_current_cartesian_velocity(), np.zeros(6)
        else:
            measured = np.array(q, dtype=float), np.array(v, dtype=float), np.zeros(self.n)
        # from the robot, not from a reference the servo does not follow (on the leash, ahead)
        following = name in self.running and gen.following(t, measured[0])
        start = gen.sample(t) if following else measured
        gen.start(t, *start, target)
        self.running.add(name)
        return True

    def start_configured(self, t: float, q, v) -> None:
        """
        At the first state: configured targets the robot is far from become trajectories.

        Far: beyond half the lead bound (see the module); the log says how far, once per task.
        The robot state must be applied to the model.
        """
        for name in self.configured:
            gen = self.trajectories.get(name)
            task = self.setup.tasks[name]
            if gen is None:
                continue
            if isinstance(task, CartesianTask):
                servo = task.servo_controller()
                target = servo.get_desired()[0]
                pose = servo.get_current_cartesian_pose()
                lin = float(np.linalg.norm(target[:3, 3] - pose[:3, 3]))
                ang = float(np.linalg.norm(pin.log3(target[:3, :3] @ pose[:3, :3].T)))
                far = max(lin / gen.lead[0], ang / gen.lead[1]) > 0.5
                how = f'{lin * 1e2:.0f} cm and {np.degrees(ang):.0f} deg'
            else:
                target = task.get_desired()[0]
                gap = np.abs(target - q)
                far = bool((gap / gen.lead > 0.5).any())
                how = f'{gap.max():.2f} rad (a joint)'
            try:
                smoothed = far and self.smooth(name, target, t, q, v)
            except ValueError as exc:  # no trajectory there (Ruckig): the step, as before
                self.say('error', f'start:{name}', f"task '{name}': {exc}; its target is a step")
                continue
            if smoothed:
                self.say(
                    'warning',
                    f'start:{name}',
                    f"task '{name}': starting {how} from its target: moved there along its "
                    'trajectory',
                )

    def stop(self, name: str) -> None:
        """Stop task ``name``'s trajectory (its target is held, reset, expired or a point)."""
        self.running.discard(name)

    def advance(self, t: float, q) -> None:
        """
        Before each update.

        Every running trajectory hands its sample at t to its task's servo, within the lead
        bound of the measured state (``q``: the joints').
        """
        if not self.running:
            return
        for name in list(self.running):
            task = self.setup.tasks[name]
            gen = self.trajectories[name]
            restarts = gen.restarts
            if isinstance(task, CartesianTask):
                servo = task.servo_controller()
                servo.set_desired(*gen.follow(t, servo.get_current_cartesian_pose()))
            else:
                task.set_desired(*gen.follow(t, q))
            if gen.restarts != restarts:
                bound = _lead_text(gen, isinstance(task, CartesianTask))
                self.say(
                    'warning',
                    f'lead:{name}',
                    f"task '{name}' cannot follow its trajectory: restarted from the measured "
                    f'state (the reference led it by more than {bound})',
                )
            if gen.finished(t):
                self.running.discard(name)


def _lead_text(gen, cartesian: bool) -> str:
    if cartesian:
        return f'{gen.lead[0] * 1e3:.0f} mm or {gen.lead[1]:.2f} rad'
    lo, hi = gen.lead.min(), gen.lead.max()
    return f'{lo:.2f} rad' if hi == lo else f'{lo:.2f}-{hi:.2f} rad (per joint)'
