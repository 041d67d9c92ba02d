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
The compiled levels below the first (optim/compiled/cascade.py) when a level in between is off.

A level whose tasks are all off (deactivated, or ramped out) is skipped: the solution above
stands, and the levels below lock to it. The compiled cascade's levels read the level above's
solution from its array; the skipped level's array kept an old solution, and the arm's torques
went 4.4 Nm away from the reference path's (found in stop 33). Switched on again, the level's
first solve is damped towards the solution above on both paths (not towards its own solution
from before it was off). The two paths in closed loop, the elbow level switched off at once or
by a 0.1 s ramp, then on again.
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import (
    add_conflicting_stack, add_standard_constraints, integrate, STACK_Q0,
)
import pytest

pytest.importorskip('numba')


@pytest.mark.parametrize('strategy', ['multi_level_weighted', 'generalized'])
@pytest.mark.parametrize('ramp', [0.0, 0.1])
def test_a_level_switched_off_leaves_the_solution_above_to_the_levels_below(strategy, ramp):
    runs = []
    for compiled in (True, False):
        robot = orca.RobotModel()
        robot.load_model_from_file(orca.default_urdf_path())
        robot.set_robot_state(STACK_Q0, np.zeros(7))
        c = orca.Controller('c', robot, strategy, 'daqp', compiled=compiled)
        add_conflicting_stack(c, 3)
        add_standard_constraints(c)
        if strategy == 'generalized':
            c.set_priority('ee', 'elbow', 0.5)
            c.set_priority('elbow', 'posture', 0.5)
        elbow = c.get_task('elbow')
        elbow.set_ramp_duration(ramp)
        c.activate_tasks_and_constraints()
        runs.append((robot, c, elbow))
    assert all(c.update(0.0, 1e-3) for _, c, _ in runs)
    assert runs[0][1].compiled_cycle.cascade is not None, runs[0][1].compiled_cycle.describe()
    q, v = STACK_Q0.copy(), np.zeros(7)
    worst = 0.0
    for k in range(1, 600):
        taus = []
        for robot, c, elbow in runs:
            if k == 100:
                elbow.deactivate()
            if k == 400:
                elbow.activate()
            robot.set_robot_state(q, v)
            assert c.update(k * 1e-3, 1e-3), (k, c.get_return_code())
            taus.append(c.get_joint_torque_command())
        worst = max(worst, np.abs(taus[0] - taus[1]).max() / max(1.0, np.abs(taus[1]).max()))
        q, v = integrate(runs[1][0], q, v, taus[1], 1e-3)
    assert worst < 1e-9, worst
    assert runs[0][2].is_activated()  # (switched on again, after its ramp)
