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
Collision avoidance on arms nobody tuned for: a small part of the seeded sweep (issue 37).

bench/bench_collision_sweep.py runs the shipped configuration plus a collision constraint (3 cm
safety distance) on seven arms, 20 random reachable targets each with a ball on the way, and the
hand sent inside its own base column; here the first PLACEMENTS of its placements (the same
generator and seed) on ARMS, and their self case. Distances measured independently: coal on the
URDF's own collision geometry (meshes), every 10 cycles.

Asserted: what the sweep finds to hold on these arms: no failed cycle, never closer than the
safety distance - 1 mm (issue 37's numbers) to the ball nor to itself; and that the ball is on
the way: the same runs without the constraint come closer than that. Not asserted, as the sweep
finds them not to hold (its output): that the hand reaches its target (the trajectory's leash
restarts it at rest 5 cm ahead of a hand held at the ball, every cycle: the hand stays there),
torque steps <= 2 Nm (the leash restarts drop the twist fed forward: up to 32 Nm on the UR5); on
the iiwa failed cycles (its wrist pair held inside the safety distance asks for a separation the
velocity limits cannot give).
"""

import importlib.util
import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ARMS = ('ur5', 'panda', 'lwr')
PLACEMENTS = 2
SEED = 0


@pytest.fixture(scope='module')
def sweep():
    spec = importlib.util.spec_from_file_location(
        'bench_collision_sweep', os.path.join(ROOT, 'bench', 'bench_collision_sweep.py'))
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # (its dataclasses look their module up there)
    spec.loader.exec_module(module)
    return module


def _bench(sweep, name):
    try:
        return sweep.Bench(name)
    except FileNotFoundError as exc:  # example-robot-data not installed
        pytest.skip(f'{name}: {exc}')


@pytest.mark.parametrize('name', ARMS)
def test_the_ball_and_the_arm_are_kept_apart(sweep, name):
    """
    No failed cycle; the meshes never closer than the safety distance - 1 mm, to ball or self.

    The constraint keeps its own hulls (which contain the meshes, inflated by 1 cm each) at the
    safety distance: the meshes stay at least as far. Without it, the same runs come closer.
    """
    bench = _bench(sweep, name)
    placements, _ = bench.placements(PLACEMENTS, SEED)
    least = sweep.SAFETY - sweep.TOLERANCE
    for i, p in enumerate(placements):
        r, without = bench.run(p, True), bench.run(p, False)
        print('%s %d: %d failed cycles, ball %.1f mm (without the constraint %.1f), self %.1f mm, '
              'largest step %.2f Nm, hand %.1f mm from its target %s'
              % (name, i, r['failures'], r['ball'] * 1e3, without['ball'] * 1e3, r['self'] * 1e3,
                 r['step'], r['error'] * 1e3, r['holds']))
        assert r['failures'] == 0, r['why']
        assert r['ball'] >= least
        assert r['self'] >= least
        assert without['ball'] < least  # the ball is on the way


@pytest.mark.parametrize('name', ARMS)
def test_a_hand_target_inside_its_own_base(sweep, name):
    """The hand sent inside its base column: no failed cycle, its watched pairs kept apart."""
    bench = _bench(sweep, name)
    r = bench.run(bench.inside(), True)
    print('%s: %d failed cycles, self %.1f mm (%s), hand %.0f mm short; %s'
          % (name, r['failures'], r['self'] * 1e3, bench.meshes.name(r['self_pair']),
             r['error'] * 1e3, r['summary']))
    assert r['failures'] == 0, r['why']
    assert r['self'] >= sweep.SAFETY - sweep.TOLERANCE
