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
The cycles of the events a control loop meets, against its steady cycle (issue 41).

The shipped configurations built by ``build_from_config`` (config/lwr_controller.yaml,
config/quadruped_controller.yaml), their ``initially_active`` objects activated, in closed loop:
the lwr on its rigid-body model (``examples.common.integrate``, from q = [0, 0.5, 0, -1.2, 0, 0.6,
0], its hand held where it starts), the quadruped standing in PyBullet at 1 kHz. Only update() is
timed (plus the event's own call where said), gc off, from the 500th cycle; each event's cycles
are set against the median of the steady cycles of the same configuration in the same process
(windows of them before each event). The events:

* ramp: the lwr's ``ee`` task deactivated then activated again (0.5 s ramps): every cycle of the
  ramp down and of the ramp up;
* contact: on the quadruped, its base leaned 12 mm away from the front left foot (as the example
  does before lifting it), ``FL_contact`` deactivated then activated again: every cycle of its
  ramps (0.2 s);
* obstacle: the lwr plus a ``collision_avoidance`` constraint, a 5 cm ball added 40 cm from the
  hand, then removed, 10 times: the add or remove call plus the next update() (as a node sees it);
* target jump: the lwr's ``ee`` target moved 5 cm at once (back and forth, 4 times): the 100
  cycles after each jump;
* failing cycle: the lwr with ``torque_limit.max`` 0.1 Nm and a ``joint_acceleration_limit`` of
  1e-3 rad/s^2 (0.1 Nm alone lets the arm fall, a solution; with both, gravity can be neither
  held nor given in to: every cycle fails), given the states of the normal lwr's loop, the two
  updated in turn in one process;
* state input: on the standing quadruped, ``set_robot_state(world_H_base, q, base_twist, v,
  gravity)`` against ``set_configuration(q, v)`` (Pinocchio's q, v), the two forms cycle by cycle:
  each call timed, and the call plus the update() after it.

Each group runs in its own process (``--child``), the groups interleaved round by round. Printed:
one line per event per round (its cycles, median, worst, the steady median, the two ratios,
failed cycles), then a table of the ratios (median over the rounds of each round's ratio) and the
issue's targets (ramp median <= 1.3x, contact median <= 1.5x, obstacle add / remove worst <= 3x,
5-argument input <= 1.05x set_configuration, failing cycle median <= 3x).

Usage: python bench/bench_events.py [--rounds 3]
"""

from __future__ import annotations

import argparse
import gc
import json
import subprocess
import sys
import time

import numpy as np

GROUPS = ('lwr', 'lwr_obstacle', 'lwr_failing', 'quadruped_contact', 'quadruped_state')
DT = 0.001
SKIP = 500  # cycles run before anything is timed
Q0 = [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]
#: event: (statistic, limit) of the issue's target; None: no target
TARGETS = {
    'ramp: ee off': ('median', 1.3),
    'ramp: ee on': ('median', 1.3),
    'target: 5 cm jump': None,
    'obstacle: add': ('worst', 3.0),
    'obstacle: remove': ('worst', 3.0),
    'failing cycle': ('median', 3.0),
    'contact: FL off': ('median', 1.5),
    'contact: FL on': ('median', 1.5),
    'state: 5-argument call': ('median', 1.05),
    'state: 5-argument + update': None,
}


def _config(name: str) -> dict:
    import orca_ros as orca
    import yaml

    with open(orca.share_path('config', f'{name}_controller.yaml')) as fh:
        return yaml.safe_load(fh)['orca_controller']['ros__parameters']


def _build(cfg: dict):
    from orca_ros.configuration import build_from_config

    setup = build_from_config(cfg)
    c = setup.controller
    for obj, active in setup.initially_active.items():
        if active:
            (c.get_task(obj) if obj in setup.tasks else c.get_constraint(obj)).activate()
    return setup


class _Samples:
    """update() times [s] and failed cycles, by event (``steady``: the reference)."""

    def __init__(self):
        self.times, self.failures = {}, {}

    def add(self, event: str, seconds: float, solved: bool = True) -> None:
        self.times.setdefault(event, []).append(seconds)
        self.failures[event] = self.failures.get(event, 0) + (not solved)

    def summary(self, references: dict) -> dict:
        """Each event's cycles, median and worst [us], its reference and its median, failures."""
        out = {}
        for event, ref in references.items():
            t = np.array(self.times[event]) * 1e6
            out[event] = {'n': int(t.size), 'median': float(np.median(t)),
                          'worst': float(t.max()), 'against': ref,
                          'ref': float(np.median(self.times[ref]) * 1e6),
                          'failures': self.failures[event]}
        return out


class _Arm:
    """The lwr's closed loop on its rigid-body model, the hand held where it starts."""

    def __init__(self, setup):
        from orca_ros.examples.common import integrate

        self.integrate = integrate
        self.setup, self.robot, self.c = setup, setup.robot, setup.controller
        self.q, self.v, self.k = np.array(Q0), np.zeros(7), 0
        self.robot.set_robot_state(self.q, self.v)
        self.hand = self.robot.get_frame_pose('link_7')
        setup.tasks['ee'].servo_controller().set_desired(self.hand.copy())

    def cycle(self, samples: _Samples | None = None, event: str = 'steady', call=None) -> None:
        """One cycle: the state in, ``call`` (when given) and update() timed, the arm moved on."""
        self.robot.set_robot_state(self.q, self.v)
        t0 = time.perf_counter()
        if call is not None:
            call()
        solved = self.c.update(self.k * DT, DT)
        seconds = time.perf_counter() - t0
        if samples is not None:
            samples.add(event, seconds, solved)
        tau = self.c.get_joint_torque_command()
        self.q, self.v = self.integrate(self.robot, self.q, self.v, tau, DT)
        self.k += 1

    def run(self, cycles: int, samples: _Samples | None = None, event: str = 'steady') -> None:
        for _ in range(cycles):
            self.cycle(samples, event)


def _ramps(run_cycle, obj, samples: _Samples, off: str, on: str, hold: int) -> None:
    """Deactivate ``obj``, time its ramp down, ``hold`` cycles later activate it, its ramp up."""
    obj.deactivate()
    while not obj.is_deactivated():
        run_cycle(samples, off)
    for _ in range(hold):
        run_cycle()
    obj.activate()
    while not obj.is_activated():
        run_cycle(samples, on)


def _lwr() -> dict:
    """Time the ee task's ramps (twice), then its target jumping 5 cm (4 times)."""
    arm, samples = _Arm(_build(_config('lwr'))), _Samples()
    ee = arm.setup.tasks['ee']
    arm.run(SKIP)
    for _ in range(2):
        arm.run(500, samples)
        _ramps(arm.cycle, ee, samples, 'ramp: ee off', 'ramp: ee on', 200)
        arm.run(300)
    for away in (True, False, True, False):  # 5 cm to the side, back to the start
        arm.run(400, samples)
        target = arm.hand.copy()
        target[1, 3] += 0.05 * away
        ee.servo_controller().set_desired(target)
        arm.run(100, samples, 'target: 5 cm jump')
        arm.run(500)
    return samples.summary({'ramp: ee off': 'steady', 'ramp: ee on': 'steady',
                            'target: 5 cm jump': 'steady'})


def _lwr_obstacle() -> dict:
    """Time a 5 cm ball added 40 cm from the hand, then removed, 10 times."""
    cfg = _config('lwr')
    cfg['constraints']['names'] = cfg['constraints']['names'] + ['collision']
    cfg['constraints']['collision'] = {'type': 'collision_avoidance'}
    arm, samples = _Arm(_build(cfg)), _Samples()
    col = arm.c.get_constraint('collision')
    pose = np.eye(4)
    pose[:3, 3] = arm.hand[:3, 3] + [0.0, -0.4, 0.0]

    def add():
        col.add_obstacle('ball', 'sphere', [0.05], pose)

    arm.run(SKIP)
    for _ in range(10):
        arm.run(200, samples)
        arm.cycle(samples, 'obstacle: add', add)
        arm.run(200)
        arm.cycle(samples, 'obstacle: remove', lambda: col.remove_obstacle('ball'))
        arm.run(100)
    return samples.summary({'obstacle: add': 'steady', 'obstacle: remove': 'steady'})


def _lwr_failing() -> dict:
    """Time the lwr that cannot hold itself and the normal lwr, in turn, on the same states."""
    from orca_ros.examples.common import integrate

    normal = _build(_config('lwr'))
    cfg = _config('lwr')
    cfg['constraints']['torque_limit']['max'] = 0.1
    # with 0.1 Nm alone the QP lets the arm fall (a solution): it may not accelerate either
    cfg['constraints']['names'] = cfg['constraints']['names'] + ['acceleration_limit']
    cfg['constraints']['acceleration_limit'] = {'type': 'joint_acceleration_limit', 'max': 1e-3}
    failing = _build(cfg)
    q, v = np.array(Q0), np.zeros(7)
    for s in (normal, failing):
        s.robot.set_robot_state(q, v)
        s.tasks['ee'].servo_controller().set_desired(s.robot.get_frame_pose('link_7'))
    samples = _Samples()
    for k in range(SKIP + 3000):
        pair = ((normal, 'steady'), (failing, 'failing cycle'))
        for s, event in pair if k % 2 else pair[::-1]:
            s.robot.set_robot_state(q, v)
            t0 = time.perf_counter()
            solved = s.controller.update(k * DT, DT)
            seconds = time.perf_counter() - t0
            if k >= SKIP:
                samples.add(event, seconds, solved)
        tau = normal.controller.get_joint_torque_command()
        q, v = integrate(normal.robot, q, v, tau, DT)
    return samples.summary({'failing cycle': 'steady'})


class _Quadruped:
    """The shipped quadruped standing in PyBullet, its base target fixed after the first cycles."""

    def __init__(self, setup, server, lean: float = 0.0):
        from orca_ros.examples import quadruped as quad

        self.quad, self.setup, self.robot, self.c = quad, setup, setup.robot, setup.controller
        self.server = server
        self.sim, self.by_name = quad.insert_standing(server)
        self.k, self.lean = 0, lean
        self.start = self.away = None  # the base's first pose, the lean's offset (x, y)

    def state_in(self) -> None:
        self.quad.state_from_sim(self.robot, self.sim, self.by_name)

    def cycle(self, samples: _Samples | None = None, event: str = 'steady') -> None:
        """One cycle: the simulated state in, update() timed, the torques out, a step."""
        self.state_in()
        self._target()
        t0 = time.perf_counter()
        solved = self.c.update(self.k * DT, DT)
        seconds = time.perf_counter() - t0
        if samples is not None:
            samples.add(event, seconds, solved)
        self.step()

    def _target(self) -> None:
        """Move the base target ``lean`` away from the front left foot over the first cycles."""
        if self.k == 0:
            frame = self.setup.tasks['base'].get_control_frame()
            self.start = self.robot.get_frame_pose(frame)
            foot = self.robot.get_frame_pose('FL_foot')[:2, 3] - self.start[:2, 3]
            self.away = -self.lean * np.sign(foot)
        if self.k < SKIP:
            s = min(1.0, self.k / (0.8 * SKIP))
            target = self.start.copy()
            target[:2, 3] += self.away * (10 * s**3 - 15 * s**4 + 6 * s**5)  # minimum jerk
            self.setup.tasks['base'].servo_controller().set_desired(target)

    def step(self) -> None:
        self.sim.set_joint_torque_command(self.c.get_joint_torque_command(), self.by_name)
        self.server.step()
        self.k += 1

    def run(self, cycles: int, samples: _Samples | None = None, event: str = 'steady') -> None:
        for _ in range(cycles):
            self.cycle(samples, event)


def _quadruped_contact() -> dict:
    """Lean the base from the front left foot; time its contact off and on again, twice."""
    from orca_ros.sim import SimServer

    setup, samples = _build(_config('quadruped')), _Samples()
    contact = setup.controller.get_constraint('FL_contact')
    with SimServer(time_step=DT) as server:
        robot = _Quadruped(setup, server, lean=0.012)
        robot.run(SKIP)
        for _ in range(2):
            robot.run(500, samples)
            _ramps(robot.cycle, contact, samples, 'contact: FL off', 'contact: FL on', 100)
            robot.run(300)
    return samples.summary({'contact: FL off': 'steady', 'contact: FL on': 'steady'})


def _quadruped_state() -> dict:
    """Give the standing quadruped its state by either form in turn; time each, with update()."""
    from orca_ros.math.rotations import quaternion_xyzw
    from orca_ros.sim import SimServer

    setup, samples = _build(_config('quadruped')), _Samples()
    robot, c = setup.robot, setup.controller
    with SimServer(time_step=DT) as server:
        loop = _Quadruped(setup, server)
        loop.run(SKIP)
        sim, by_name, gravity = loop.sim, loop.by_name, loop.quad.GRAVITY
        for k in range(3000):
            T, twist = sim.get_world_to_base_transform(), sim.get_base_velocity()
            qj, vj = sim.get_joint_positions(by_name), sim.get_joint_velocities(by_name)
            if k % 2:
                R = T[:3, :3]
                q = np.concatenate((T[:3, 3], quaternion_xyzw(R), qj))
                v = np.concatenate((twist[:3] @ R, twist[3:] @ R, vj))
                t0 = time.perf_counter()
                robot.set_configuration(q, v)
                call, both = 'set_configuration', 'set_configuration + update'
            else:
                t0 = time.perf_counter()
                robot.set_robot_state(T, qj, twist, vj, gravity)
                call, both = 'state: 5-argument call', 'state: 5-argument + update'
            t1 = time.perf_counter()
            solved = c.update(loop.k * DT, DT)
            t2 = time.perf_counter()
            samples.add(call, t1 - t0)
            samples.add(both, t2 - t0, solved)
            loop.step()
    return samples.summary({'state: 5-argument call': 'set_configuration',
                            'state: 5-argument + update': 'set_configuration + update'})


def child(group: str) -> None:
    run = {'lwr': _lwr, 'lwr_obstacle': _lwr_obstacle, 'lwr_failing': _lwr_failing,
           'quadruped_contact': _quadruped_contact, 'quadruped_state': _quadruped_state}[group]
    gc.collect()
    gc.disable()
    try:
        out = run()
    finally:
        gc.enable()
    print(json.dumps(out))


def _met(event: str, median: float, worst: float) -> tuple[str, str]:
    target = TARGETS.get(event)
    if target is None:
        return '-', '-'
    stat, limit = target
    value = median if stat == 'median' else worst
    return f'{stat} <= {limit:g}x', 'met' if value <= limit else 'not met'


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--rounds', type=int, default=3)
    parser.add_argument('--child', choices=GROUPS)
    args = parser.parse_args()
    if args.child:
        child(args.child)
        return 0
    ratios = {}  # event: [(median ratio, worst ratio) per round]
    for r in range(args.rounds):
        for group in GROUPS:
            out = subprocess.run([sys.executable, __file__, '--child', group],
                                 capture_output=True, text=True, check=True)
            for event, s in json.loads(out.stdout.strip().splitlines()[-1]).items():
                m, w = s['median'] / s['ref'], s['worst'] / s['ref']
                ratios.setdefault(event, []).append((m, w))
                failed = f", {s['failures']} failed" if s['failures'] else ''
                print(f"round {r + 1} {event:<28}{s['n']:5d} cycles{failed}: median "
                      f"{s['median']:7.1f} us, worst {s['worst']:7.1f} us; {s['against']} "
                      f"{s['ref']:6.1f} us: {m:5.2f}x, {w:6.2f}x", flush=True)
    print(f'\nmedian and worst over the steady median (state: over set_configuration), median '
          f'of the {args.rounds} rounds:')
    print(f"{'event':<28}{'median':>8}{'worst':>9}  {'target':<20}met")
    for event in TARGETS:
        m, w = (float(np.median(x)) for x in zip(*ratios[event]))
        target, met = _met(event, m, w)
        print(f'{event:<28}{m:7.2f}x{w:8.2f}x  {target:<20}{met}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
