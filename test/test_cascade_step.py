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
Every level of a stack in one kernel call (optim/compiled/cascade_step.py), against a call each.

Two compiled controllers in one closed loop on the lwr's three-level stack: one runs the cycle
with cascade_step, the other with it switched off (the one-call first level, then the cascade's
call per level, as before it). Through what makes the kernel stop and the cascade take over
(a level that fails within an iteration cap of 2, for the first 0.4 s, then is dropped), and
through what changes the levels' modes between cycles (priorities, also in a run of steady
cycles; the lower levels' damping, a task ramped out and in): the same torques every cycle, the
same levels dropped.
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import (
    add_conflicting_stack, add_standard_constraints, integrate, STACK_Q0,
)
import pytest

pytest.importorskip('numba')


def _controller(strategy, one_call):
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(STACK_Q0, np.zeros(7))
    c = orca.Controller('c', robot, strategy, 'daqp')
    add_conflicting_stack(c, 3)
    add_standard_constraints(c)
    if strategy == 'generalized':
        c.set_priority('ee', 'elbow', 0.5)
        c.set_priority('elbow', 'posture', 0.5)
    c.get_task('elbow').set_ramp_duration(0.05)
    # a level fails now and then: the kernel stops; no deadline that a busy machine could reach
    # (the two controllers' time models would cap their solves apart)
    c.set_solver_budget(time_budget=10.0, max_iterations=2)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 1e-3)
    fused = c.compiled_cycle.fused
    assert fused.cascade_step is not None, c.compiled_cycle.describe()
    stops = []
    if one_call:
        cs = fused.cascade_step
        cs.run = lambda *a, run=cs.run: _record(run, stops, *a)
    else:
        fused.cascade_step = None
    return robot, c, stops


def _record(run, stops, *args):
    out = run(*args)
    stops.append(out[1])
    return out


@pytest.mark.parametrize('strategy', ['multi_level_weighted', 'generalized'])
def test_one_call_for_every_level_is_the_call_per_level(strategy):
    runs = [_controller(strategy, one_call) for one_call in (True, False)]
    q, v = STACK_Q0.copy(), np.zeros(7)
    for k in range(1, 1200):
        t = k * 1e-3
        for _, c, _ in runs:
            if k == 400:
                c.set_solver_budget(time_budget=10.0)  # no cap: the kernel takes every level
            if k == 300 and strategy == 'generalized':
                c.set_priority('elbow', 'posture', 0.8)
            if k == 500:
                c.set_lower_level_damping(2.0)
            if k == 600 and strategy == 'generalized':  # in steady cycles (every level warm)
                c.set_priority('ee', 'elbow', 0.3)
            if k == 700:
                c.get_task('elbow').deactivate()
            if k == 900:
                c.get_task('elbow').activate()
        taus = []
        for robot, c, _ in runs:
            robot.set_robot_state(q, v)
            c.update(t, 1e-3)
            taus.append(c.get_joint_torque_command())
        np.testing.assert_allclose(taus[0], taus[1], rtol=0, atol=1e-12, err_msg=str(k))
        q, v = integrate(runs[0][0], q, v, taus[0], 1e-3)
    (_, one, stops), (_, per_level, _) = runs
    assert one.dropped_levels == per_level.dropped_levels > 0
    # the kernel took every level in most cycles, and stopped at a level below in others
    assert stops.count(3) > 600, {s: stops.count(s) for s in set(stops)}
    assert any(s in (1, 2) for s in stops), {s: stops.count(s) for s in set(stops)}
    assert np.linalg.norm(v) > 0.1  # the stack moved the arm
