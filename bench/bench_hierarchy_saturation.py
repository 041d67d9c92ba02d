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
Hierarchies where the limits bind: torque steps per cycle and per step of an alpha sweep.

Issue 37, acceptance 3. The 3-level stack of ``examples.common.add_conflicting_stack`` (end
effector level 0, an elbow pulling elsewhere level 1, posture level 2) on the lwr (urdf/lwr.urdf),
the iiwa (pybullet_data's kuka_iiwa) and the Panda (example-robot-data, fingers included), under
the URDF's torque, position and velocity limits, closed on the rigid-body model
(``examples.common.integrate``, 1 ms cycles, 2 s). Targets: seeded draws, the hand 20-35 cm and
the elbow 20-50 cm from where they start (PD gains 100 / 20: the joints run into their velocity
limits, the Panda's into its torque limits), and one hand target 0.9 m away (beyond reach: the arm
ends stretched, at the singularity of its hand's position).

Per scenario, the largest torque step per cycle (all joints) and the cycles above 2 Nm, over the
whole run and after the first 20 ms (the tasks switched on at once: the switch-on transient), of
  * ``ee``: the hand's task alone (what level 0 does by itself: steps no hierarchy can remove),
  * ``one``: the three tasks in one weighted level (ONE_LEVEL_WEIGHTED),
  * ``multi``: MULTI_LEVEL_WEIGHTED,
  * ``gen``: GENERALIZED, every priority 0.5;
the cycles of the multi run with a torque at its limit and with a joint at its velocity limit;
and alpha sweeps at saturated states of the multi run (a joint at its velocity or torque limit):
a GENERALIZED controller at that state from alpha 0 to 1 in 1000 steps, one update per step (as
test_default_hierarchies.py sweeps), its largest step inside [0, 0.999] and its last (to 1).

Usage: python bench/bench_hierarchy_saturation.py [--arms lwr,iiwa,panda] [--draws 3]
       [--python] (the reference path instead of the compiled cycle)
"""

from __future__ import annotations

import argparse
import glob
import os
import sys

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_conflicting_stack, integrate, STACK_ARMS

DT = 0.001
SWITCH_ON = 20  # cycles


def _urdf(which: str) -> str:
    if which == 'lwr':
        return orca.default_urdf_path()
    if which == 'iiwa':
        import pybullet_data

        return os.path.join(pybullet_data.getDataPath(), 'kuka_iiwa', 'model.urdf')
    for p in sys.path:
        hit = glob.glob(f'{p}/cmeel.prefix/share/example-robot-data/robots/'
                        'panda_description/urdf/panda.urdf')
        if hit:
            return hit[0]
    raise FileNotFoundError('example-robot-data')


#: arm: (end effector frame, elbow frame, start posture)
ARMS = STACK_ARMS


def scenarios(which: str, draws: int):
    """Return the (hand, elbow) target offsets of an arm: seeded draws, then one beyond reach."""
    rng = np.random.default_rng(sorted(ARMS).index(which) + 37)
    out = []
    for _ in range(draws):
        d = rng.normal(size=3)
        e = rng.normal(size=3)
        out.append((d * rng.uniform(0.2, 0.35) / np.linalg.norm(d),
                    e * rng.uniform(0.2, 0.5) / np.linalg.norm(e)))
    out.append((np.array([0.9, 0.0, 0.0]), None))
    return out


def make(which, strategy, offsets, alpha=None, n_tasks=3, compiled=True):
    """Make the arm's stack with its hand (and elbow) targets moved by ``offsets``."""
    ee, elbow, q0 = ARMS[which]
    q0 = np.asarray(q0, dtype=float)
    robot = orca.RobotModel()
    robot.load_model_from_file(_urdf(which))
    robot.set_robot_state(q0, np.zeros(q0.size))
    c = orca.Controller(which, robot, strategy, compiled=compiled)
    tasks = add_conflicting_stack(c, n_tasks, frames=(ee, elbow), posture=q0)
    for (name, frame), off in zip((('ee', ee), ('elbow', elbow)), offsets):
        if off is not None and name in tasks:
            target = robot.get_frame_pose(frame)
            target[:3, 3] += off
            tasks[name].servo_controller().set_desired(target)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position_limit')
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity_limit')
    c.activate_tasks_and_constraints()
    if alpha is not None:
        set_priorities(c, alpha)
    return robot, c, q0


def set_priorities(c, alpha: float) -> None:
    for hi in ('ee', 'elbow'):
        for lo in ('elbow', 'posture'):
            if c.get_task(hi).level < c.get_task(lo).level:
                c.set_priority(hi, lo, alpha)


def closed_loop(robot, c, q0, seconds=2.0):
    """Torques and states (q, v) of every cycle; the cycles at a torque / velocity limit."""
    q, v = q0.copy(), np.zeros(q0.size)
    tmax, vmax = robot.get_joint_torque_limits(), robot.get_joint_velocity_limits()
    taus, states, at_torque, at_speed = [], [], [], []
    for k in range(int(round(seconds / DT))):
        robot.set_robot_state(q, v)
        if not c.update(k * DT, DT):
            raise RuntimeError(f'{c.name}: cycle {k} failed ({c.get_return_code().value})')
        tau = c.get_joint_torque_command().copy()
        taus.append(tau)
        states.append((q.copy(), v.copy()))
        at_torque.append(bool(np.any(np.abs(tau) >= tmax * (1.0 - 1e-6))))
        at_speed.append(bool(np.any(np.abs(v) >= vmax * (1.0 - 1e-3))))
        q, v = integrate(robot, q, v, tau, DT)
    return np.array(taus), states, np.array(at_torque), np.array(at_speed)


def steps(taus: np.ndarray) -> np.ndarray:
    """Return the largest joint's torque step from each cycle to the next."""
    return np.abs(np.diff(taus, axis=0)).max(axis=1)


def sweep(which, offsets, q, v, compiled=True, n=1000):
    """Alpha 0 -> 1 in n steps at the state (q, v): (largest step inside, last step)."""
    robot, c, _ = make(which, 'generalized', offsets, alpha=0.0, compiled=compiled)
    robot.set_robot_state(q, v)
    assert c.update(0.0, DT)
    taus = [c.get_joint_torque_command().copy()]
    for i in range(1, n + 1):
        set_priorities(c, i / n)
        assert c.update(i * DT, DT)
        taus.append(c.get_joint_torque_command().copy())
    s = steps(np.array(taus))
    return float(s[:-1].max()), float(s[-1])


def saturated_states(states, at_torque, at_speed, count=3):
    """Up to ``count`` states spread over the cycles at a limit (torque ones first)."""
    k_t, k_v = np.flatnonzero(at_torque), np.flatnonzero(at_speed & ~at_torque)
    picks = list(k_t[:: max(1, len(k_t) // count)][:count])
    picks += list(k_v[:: max(1, len(k_v) // count)][: count - len(picks)])
    return [states[k] for k in picks]


def scenario(which, offsets, compiled=True, sweeps=3):
    """One scenario's figures (a dict; see the module's docstring)."""
    row = {}
    runs = (('ee', 'multi_level_weighted', None, 1), ('one', 'one_level_weighted', None, 3),
            ('multi', 'multi_level_weighted', None, 3), ('gen', 'generalized', 0.5, 3))
    for key, strategy, alpha, n in runs:
        robot, c, q0 = make(which, strategy, offsets, alpha, n, compiled)
        taus, states, at_t, at_v = closed_loop(robot, c, q0)
        s = steps(taus)
        row[key] = (float(s.max()), int(np.sum(s > 2.0)), float(s[SWITCH_ON:].max()),
                    int(np.sum(s[SWITCH_ON:] > 2.0)))
        if key == 'multi':
            row['at_torque'], row['at_speed'] = int(at_t.sum()), int(at_v.sum())
            picked = saturated_states(states, at_t, at_v, sweeps)
    row['sweeps'] = [sweep(which, offsets, q, v, compiled) for q, v in picked]
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('--arms', default='lwr,iiwa,panda')
    ap.add_argument('--draws', type=int, default=3,
                    help='seeded targets per arm (+1 beyond reach)')
    ap.add_argument('--sweeps', type=int, default=3, help='alpha sweeps per scenario')
    ap.add_argument('--python', action='store_true', help='the reference path')
    args = ap.parse_args(argv)
    print('largest torque step per cycle, Nm (cycles > 2 Nm): whole run / after the first '
          f'{SWITCH_ON} ms; cycles at a torque / velocity limit (multi); alpha sweeps at '
          'saturated states: largest step inside [0, 0.999] / last step')
    worst = {}
    for which in args.arms.split(','):
        for offsets in scenarios(which, args.draws):
            row = scenario(which, offsets, not args.python, args.sweeps)
            label = f'{which} hand {np.round(offsets[0], 2)}'
            cells = []
            for key in ('ee', 'one', 'multi', 'gen'):
                a, na, b, nb = row[key]
                cells.append(f'{key} {a:6.2f} ({na:4d}) / {b:6.2f} ({nb:4d})')
                w = worst.setdefault(key, [0.0, 0.0])
                w[0], w[1] = max(w[0], a), max(w[1], b)
            sw = ' '.join(f'{a:.2f}/{b:.2f}' for a, b in row['sweeps'])
            for a, b in row['sweeps']:
                w = worst.setdefault('sweep', [0.0, 0.0])
                w[0], w[1] = max(w[0], a), max(w[1], b)
            print(f'{label:<34}' + ' | '.join(cells)
                  + f" | limits {row['at_torque']:4d} / {row['at_speed']:4d} | sweeps {sw}",
                  flush=True)
    print('worst: ' + ', '.join(f'{k} {a:.2f} / {b:.2f}' for k, (a, b) in worst.items()))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
