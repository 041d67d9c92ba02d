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
Controller.update() of the shipped configurations, as users get them (issue 41).

config/quadruped_controller.yaml built by ``build_from_config``, standing in PyBullet at 1 kHz
(the example's standing start, its base swaying 3 cm), and the same YAML without its balance
constraint; config/lwr_controller.yaml holding the arm. Each variant runs in its own process,
the variants interleaved round by round; only update() is timed, from the 500th cycle. Printed:
each variant's median and p99 per round, and the ratio of the medians to the quadruped without
balance, round by round.

Usage: python bench/bench_shipped.py [--rounds 3] [--cycles 3000]
"""

from __future__ import annotations

import argparse
import gc
import json
import subprocess
import sys
import time

import numpy as np

VARIANTS = ('quadruped', 'quadruped_without_balance', 'lwr')


def _setup(variant: str):
    import orca_ros as orca
    from orca_ros.configuration import build_from_config
    import yaml

    name = 'lwr' if variant == 'lwr' else 'quadruped'
    with open(orca.share_path('config', f'{name}_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    if variant == 'quadruped_without_balance':
        names = cfg['constraints']['names']
        cfg['constraints']['names'] = [n for n in names if n != 'balance']
    setup = build_from_config(cfg)
    for obj, active in setup.initially_active.items():
        if active:
            c = setup.controller
            (c.get_task(obj) if obj in setup.tasks else c.get_constraint(obj)).activate()
    return setup


def _run(variant: str, cycles: int) -> list[float]:
    from orca_ros.examples import quadruped as quad
    import orca_ros as orca
    from orca_ros.sim import SimServer

    setup = _setup(variant)
    c, robot = setup.controller, setup.robot
    if variant != 'lwr':
        base = setup.tasks['base'].servo_controller()
        frame = setup.tasks['base'].get_control_frame()
    times = []
    with SimServer(time_step=0.001) as server:
        if variant == 'lwr':
            sim = server.insert_model_from_urdf_file(orca.default_urdf_path(), fixed_base=True)
            names = robot.get_joint_names()
            by_name = sim.joint_map(names)
            sim.set_model_configuration(names, [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0])
        else:
            sim, by_name = quad.insert_standing(server)
        gc.disable()
        try:
            for k in range(cycles):
                if variant == 'lwr':
                    robot.set_robot_state(sim.get_joint_positions(by_name),
                                          sim.get_joint_velocities(by_name))
                else:
                    quad.state_from_sim(robot, sim, by_name)
                    if k == 0:
                        start = robot.get_frame_pose(frame)
                    target = start.copy()
                    target[1, 3] += 0.03 * np.sin(2 * np.pi * 0.5 * k * 0.001)
                    base.set_desired(target)
                t0 = time.perf_counter()
                c.update(k * 0.001, 0.001)
                times.append(time.perf_counter() - t0)
                sim.set_joint_torque_command(c.get_joint_torque_command(), by_name)
                server.step()
        finally:
            gc.enable()
    return times[500:]


def child(variant: str, cycles: int) -> None:
    times = np.array(_run(variant, cycles)) * 1e6
    print(json.dumps({'median': float(np.median(times)), 'p99': float(np.percentile(times, 99))}))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--rounds', type=int, default=3)
    parser.add_argument('--cycles', type=int, default=3000)
    parser.add_argument('--child', choices=VARIANTS)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.cycles)
        return 0
    results = {v: [] for v in VARIANTS}
    for r in range(args.rounds):
        for v in VARIANTS:
            out = subprocess.run([sys.executable, __file__, '--child', v, '--cycles',
                                  str(args.cycles)], capture_output=True, text=True, check=True)
            results[v].append(json.loads(out.stdout.strip().splitlines()[-1]))
        ratio = results['quadruped'][-1]['median'] / results['quadruped_without_balance'][-1][
            'median']
        print(f'round {r + 1}: ' + ', '.join(
            f"{v} {results[v][-1]['median']:.1f} us (p99 {results[v][-1]['p99']:.1f})"
            for v in VARIANTS) + f'; quadruped / without balance {ratio:.2f}')
    pairs = zip(results['quadruped'], results['quadruped_without_balance'])
    ratios = [a['median'] / b['median'] for a, b in pairs]
    print(f'quadruped YAML / the same without balance: median of rounds {np.median(ratios):.2f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
