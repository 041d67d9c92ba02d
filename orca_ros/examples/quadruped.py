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
A 12-DoF quadruped standing on four point contacts.

stand, shift the base in a sinusoid, lift a foot.

The controller (core API only): four unilateral contacts (friction pyramid, ramped normal force), a
6-D Cartesian task on the trunk in the world frame, a posture task, a swing-foot task used only
while a foot is in the air, torque / position / velocity limits, the CoM over the feet (balance).
:func:`run_in_pybullet` closes the loop on PyBullet and logs what the acceptance tests check
(tracking, foot slip, cone margins, normal-force steps).

Another quadruped: its URDF (and an SRDF with its standing pose), the trunk, feet and standing
configuration derived from them (:mod:`.quadruped_robot`).

Run: ``python -m orca_ros.examples.quadruped [urdf [--srdf SRDF]] [--scenario stand|shift|lift|all]
[--gui] [--solver osqp]``
"""

from __future__ import annotations

import argparse

import numpy as np
import pinocchio as pin

from .quadruped_log import dynamics_residual, record_step, RunLog  # noqa: F401 (re-exported)
from .quadruped_robot import (  # noqa: F401 (re-exported)
    FOOT_RADIUS,
    from_urdf,
    LEGS,
    Quadruped,
    shipped,
    STAND_HEIGHT,
    STAND_Q,
)
from .. import (
    BalanceConstraint,
    CartesianTask,
    Contact,
    Controller,
    JointAccelerationTask,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
    Logger,
    MinJerkPositionTrajectory,
    QPSolver,
    ResolutionStrategy,
    RobotModel,
)

GRAVITY = np.array([0.0, 0.0, -9.81])


def quadruped_urdf() -> str:
    return shipped().urdf


def make_robot(urdf: str | None = None, quad: Quadruped | None = None) -> RobotModel:
    """Load the quadruped (default: the shipped one) standing, in the world frame."""
    quad = quad or shipped()
    robot = RobotModel('quadruped')
    robot.load_model_from_file(urdf or quad.urdf, floating_base=True)
    robot.set_base_frame('world')
    T = np.eye(4)
    T[:3, :3] = pin.Quaternion(np.asarray(quad.q[3:7])).toRotationMatrix()
    T[:3, 3] = quad.home
    n = quad.joints.size
    robot.set_robot_state(T, quad.joints, np.zeros(6), np.zeros(n), GRAVITY)
    return robot


class QuadrupedController:
    """The standing controller and the handles the scenarios use."""

    def __init__(
        self,
        robot: RobotModel,
        solver='daqp',
        mu: float = 0.8,
        margin: float = 0.1,
        contact_ramp: float = 0.2,
        strategy=ResolutionStrategy.ONE_LEVEL_WEIGHTED,
        horizontal_weight: float = 5.0,
        contact_velocity_gain: float = 200.0,
        joint_braking: float = 100.0,
        quad: Quadruped | None = None,
    ):
        """
        Make the standing controller.

        Three settings make it hold a 150 N, 0.1 s push from any side (in PyBullet,
        ``test_contact_velocity_feedback.py``: no failed cycle, tilt under 10 deg; without any
        one of them it tips over):

        * ``horizontal_weight``: the trunk's x and y rows weigh this much more than its height
          and orientation. The feet can only resist a push as hard as they are pressed down;
          with equal weights, or too small a ratio, the trunk's height servo unloaded them once
          the push had lifted the trunk, and the robot tipped over.
        * ``contact_velocity_gain``: velocity feedback in the feet's existence conditions
          (a foot set sliding comes back to rest; without it, a push slides the feet far
          further).
        * ``joint_braking`` [rad/s^2]: the deceleration the position limits count on
          (``JointPositionLimitConstraint.set_max_acceleration``). The library's 5 rad/s^2 suits an
          arm; these legs (25 Nm on links of 0.25-1 kg) brake much harder, and at 5 a knee 1.2 rad
          from its limit may not turn faster than 3.5 rad/s: the unloaded legs of a pushed robot
          then cannot follow it (the push is lost at low values, held at the default).

        ``quad``: the trunk, feet and standing posture (default: the shipped quadruped's).
        """
        quad = quad or shipped()
        self.robot = robot
        self.feet = dict(quad.feet)
        c = self.controller = Controller(
            'quadruped', robot, strategy, QPSolver.from_string(str(solver))
        )
        self.contacts = {}
        for leg in LEGS:
            ct = Contact(f'{leg}_contact', quad.feet[leg])
            ct.set_friction_coefficient(mu)
            ct.set_margin(margin)
            ct.set_maximum_normal_force(300.0)
            ct.set_ramp_duration(0.0)  # standing from the first cycle; later switches ramp
            ct.set_velocity_feedback_gain(contact_velocity_gain)
            self.contacts[leg] = c.add_constraint(ct)
        self.contact_ramp = contact_ramp
        self._started = False
        self.base = c.add_task(CartesianTask, 'base')
        self.base.set_control_frame(quad.trunk)
        pid = self.base.servo_controller().pid()
        pid.set_proportional_gain([900.0, 900.0, 900.0, 400.0, 400.0, 400.0])
        pid.set_derivative_gain([60.0, 60.0, 60.0, 40.0, 40.0, 40.0])
        self.base.set_selection_vector([horizontal_weight] * 2 + [1.0] * 4)
        self.posture = c.add_task(JointAccelerationTask, 'posture')
        self.posture.set_weight(1e-3)
        self.posture.pid().set_proportional_gain(25.0)
        self.posture.pid().set_derivative_gain(10.0)
        self.posture.set_desired(quad.joints)
        self.swing = {}
        for leg in LEGS:
            t = c.add_task(CartesianTask, f'{leg}_swing')
            t.set_control_frame(quad.feet[leg])
            t.set_selection_vector([1, 1, 1, 0, 0, 0])
            t.servo_controller().pid().set_proportional_gain(900.0)
            t.servo_controller().pid().set_derivative_gain(60.0)
            t.set_ramp_duration(0.05)
            self.swing[leg] = t
        self.torque_limit = c.add_constraint(JointTorqueLimitConstraint, 'torque_limit')
        c.add_constraint(JointPositionLimitConstraint, 'position_limit').set_max_acceleration(
            joint_braking
        )
        c.add_constraint(JointVelocityLimitConstraint, 'velocity_limit')
        # the CoM 2 cm inside the feet: lifting a foot leans it 2-3 cm inside the three others
        c.add_constraint(BalanceConstraint('balance', margin=0.02))
        for obj in [self.base, self.posture, self.torque_limit] + list(self.contacts.values()):
            obj.activate()
        for obj in c.get_constraints():
            obj.activate()

    def update(self, t: float, dt: float) -> bool:
        ok = self.controller.update(t, dt)
        if not self._started:
            self._started = True
            for ct in self.contacts.values():
                ct.set_ramp_duration(self.contact_ramp)
        return ok

    def set_base_target(self, position, velocity=None, acceleration=None) -> None:
        T = np.eye(4)
        T[:3, 3] = position
        vel = np.zeros(6)
        acc = np.zeros(6)
        if velocity is not None:
            vel[:3] = velocity
        if acceleration is not None:
            acc[:3] = acceleration
        self.base.servo_controller().set_desired(T, vel, acc)

    def contact_forces(self) -> np.ndarray:
        """(4, 3) contact forces of the last solution, world axes."""
        x = self.controller.get_reduced_solution()
        return np.array([self.contacts[leg].get_wrench(x)[:3] for leg in LEGS])


def sinusoid(s: float, amplitude: float, period: float, duration: float):
    """
    Return (y, y', y'') of a sway that starts and ends at rest.

    y = A sin(2 pi s / period) whose amplitude fades in over the first half period and out over the
    last one (quintic envelope): the reference starts and ends at rest, with no step in velocity.
    """
    w = 2 * np.pi / period
    half = period / 2
    sin, cos = np.sin(w * s), np.cos(w * s)
    e, de, dde = 1.0, 0.0, 0.0
    for x, sign in (((s / half), 1.0), (((duration - s) / half), -1.0)):
        if x < 1.0:
            x = max(x, 0.0)
            e = 10 * x**3 - 15 * x**4 + 6 * x**5
            de = sign * (30 * x**2 - 60 * x**3 + 30 * x**4) / half
            dde = (60 * x - 180 * x**2 + 120 * x**3) / half**2
    A = amplitude
    return (
        A * e * sin,
        A * (de * sin + e * w * cos),
        A * (dde * sin + 2 * de * w * cos - e * w * w * sin),
    )


def insert_standing(server, quad: Quadruped | None = None):
    """Insert the quadruped standing 1 mm above the ground; return (sim model, joint map)."""
    quad = quad or shipped()
    sim = server.insert_model_from_urdf_file(
        quad.urdf,
        position=quad.home + [0.0, 0.0, 0.001],
        orientation=quad.q[3:7],
        fixed_base=False,
    )
    names = make_robot(quad=quad).get_joint_names()
    sim.set_model_configuration(names, quad.joints)
    return sim, sim.joint_map(names)  # Pinocchio's joint order <-> PyBullet's (the file's)


def state_from_sim(robot: RobotModel, sim, by_name) -> None:
    """Give the robot model the simulated state (base pose and twist, joints by name)."""
    robot.set_robot_state(
        sim.get_world_to_base_transform(),
        sim.get_joint_positions(by_name),
        sim.get_base_velocity(),
        sim.get_joint_velocities(by_name),
        GRAVITY,
    )


def run_in_pybullet(
    scenario: str = 'all',
    solver='daqp',
    gui: bool = False,
    stand_time: float = 10.0,
    shift_time: float = 5.0,
    amplitude: float = 0.05,
    period: float = 2.0,
    lift: float = 0.05,
    quad: Quadruped | None = None,
):
    """
    Run the closed loop on PyBullet at 1 kHz; returns (log, phase boundaries dict).

    ``quad``: the quadruped (default: the shipped one).
    """
    from ..sim import SimServer

    quad = quad or shipped()
    robot = make_robot(quad=quad)
    qc = QuadrupedController(robot, solver, quad=quad)
    c = qc.controller
    home = np.array(quad.home)
    log = RunLog()
    phases = {}
    with SimServer(gui=gui, time_step=0.001) as server:
        sim, by_name = insert_standing(server, quad)
        dt = server.time_step
        state = {'t': 0.0}

        def step(target, vel=None, acc=None):
            t = state['t']
            state_from_sim(robot, sim, by_name)
            qc.set_base_target(target, vel, acc)
            if not qc.update(t, dt):
                log.failures += 1
            sim.set_joint_torque_command(c.get_joint_torque_command(), by_name)
            server.step()
            record_step(log, qc, sim, t, target, quad.foot_radius)
            state['t'] = t + dt

        def hold(target, duration):
            for _ in range(int(round(duration / dt))):
                step(target)

        # stand (the first 0.5 s settle the 1 mm drop)
        phases['stand'] = (
            state['t'],
            state['t'] + (stand_time if scenario in ('stand', 'all') else 1.0),
        )
        hold(home, phases['stand'][1] - phases['stand'][0])
        if scenario in ('shift', 'all'):
            t0 = state['t']
            for k in range(int(round(shift_time / dt))):
                y, vy, ay = sinusoid(k * dt, amplitude, period, shift_time)
                step(home + [0, y, 0], [0, vy, 0], [0, ay, 0])
            phases['shift'] = (t0, state['t'])
            hold(home, 0.5)
        if scenario in ('lift', 'all'):
            phases['lift'] = _lift_foot(qc, step, hold, home, state, dt, lift)
    return log, phases, qc


def _lift_foot(qc, step, hold, home, state, dt, lift, leg='FL'):
    """
    Move the base over the other three feet.

    Unload and lift ``leg`` by ``lift``, set it down, reload.
    """
    t0 = state['t']
    foot = qc.robot.get_frame_pose(qc.feet[leg])[:2, 3] - home[:2]
    # toward the opposite foot: CoM inside the triangle
    lean = home + np.r_[-0.012 * np.sign(foot), 0.0]
    traj = MinJerkPositionTrajectory(0.5)
    traj.reset_trajectory(home, lean)
    for k in range(int(round(0.5 / dt))):
        p, v, a = traj.get_desired(k * dt)
        step(p, v, a)
    contact, swing = qc.contacts[leg], qc.swing[leg]
    contact.deactivate()
    while not contact.is_deactivated():
        step(lean)
    foot0 = qc.robot.get_frame_pose(qc.feet[leg])
    swing.servo_controller().set_desired(foot0)
    swing.activate()
    for up, duration in ((lift, 0.6), (-lift - 0.003, 0.6)):
        start = qc.robot.get_frame_pose(qc.feet[leg])[:3, 3] if up < 0 else foot0[:3, 3]
        goal = foot0[:3, 3] + [0.0, 0.0, max(up, -0.003)]
        traj = MinJerkPositionTrajectory(duration)
        traj.reset_trajectory(start, goal)
        for k in range(int(round(duration / dt))):
            p, v, a = traj.get_desired(k * dt)
            T = foot0.copy()
            T[:3, 3] = p
            vel = np.zeros(6)
            acc = np.zeros(6)
            vel[:3], acc[:3] = v, a
            swing.servo_controller().set_desired(T, vel, acc)
            step(lean)
        hold(lean, 0.2)
    contact.activate()
    swing.deactivate()
    hold(lean, 0.4)
    traj = MinJerkPositionTrajectory(0.5)
    traj.reset_trajectory(lean, home)
    for k in range(int(round(0.5 / dt))):
        p, v, a = traj.get_desired(k * dt)
        step(p, v, a)
    hold(home, 0.5)
    return (t0, state['t'])


def main(argv=None) -> int:
    rest = Logger.parse_argv(argv)
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--scenario', default='all', choices=['stand', 'shift', 'lift', 'all'])
    ap.add_argument('--solver', default='daqp', choices=[s.value for s in QPSolver])
    ap.add_argument('--gui', action='store_true')
    ap.add_argument('--stand-time', type=float, default=10.0)
    ap.add_argument('urdf', nargs='?', default=None, help='a quadruped (default: the shipped one)')
    ap.add_argument('--srdf', default=None, help="SRDF with the URDF's 'standing' pose")
    ap.add_argument('--foot-radius', type=float, default=None, help="[m] (default: the URDF's)")
    args = ap.parse_args(rest)
    quad = args.urdf and from_urdf(args.urdf, args.srdf, foot_radius=args.foot_radius)
    log, phases, _ = run_in_pybullet(
        args.scenario, args.solver, args.gui, stand_time=args.stand_time, quad=quad
    )
    report = summarize(log, phases)
    for k, v in report.items():
        print(f'{k:<34}{v:.4g}' if isinstance(v, float) else f'{k:<34}{v}')
    return 0 if log.failures == 0 else 1


def summarize(log: RunLog, phases: dict) -> dict:
    a = log.arrays()
    t = a['t']
    out = {'QP failures': log.failures}
    for name, (t0, t1) in phases.items():
        m = (t >= t0 + (0.5 if name == 'stand' else 0.0)) & (t < t1)
        err = np.linalg.norm(a['base'][m] - a['base_target'][m], axis=1)
        out[f'{name}: base error rms [mm]'] = float(np.sqrt(np.mean(err**2)) * 1e3)
        out[f'{name}: base error max [mm]'] = float(err.max() * 1e3)
    out['max cone value [N] (<= 0 inside)'] = float(a['cone'].max())
    out['max normal force step [N]'] = float(np.abs(np.diff(a['forces'][:, :, 2], axis=0)).max())
    return out


if __name__ == '__main__':
    raise SystemExit(main())
