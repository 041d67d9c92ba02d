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
Fill the kernels' disk cache ahead of time: ``python -m orca_ros.optim.compiled.warm``.

Configures a controller of each kind the kernels are typed for (fixed base; floating base without
contacts; with contacts; levels below the first: two strict levels, as the shipped arm's, and three
GENERALIZED ones), so that a later process loads them instead of compiling them (several times
longer).
The test command runs it first, so that no test's timing includes a cold compile (one test,
test_compiled_startup.py, measures that on purpose, in a folder of its own).
"""

from __future__ import annotations

import sys
import time


def main() -> int:
    import numpy as np  # noqa: PLC0415
    import orca_ros as orca  # noqa: PLC0415
    from orca_ros.examples import quadruped  # noqa: PLC0415
    from orca_ros.examples.common import (  # noqa: PLC0415
        add_conflicting_stack, add_standard_constraints, STACK_Q0,
    )

    t0 = time.perf_counter()
    for floating in (False, True):
        robot = orca.RobotModel()
        robot.load_model_from_file(orca.default_urdf_path(), floating_base=floating)
        robot.set_base_frame('world')
        c = orca.Controller('warm', robot)
        c.add_task(orca.CartesianTask, 'ee').set_control_frame('link_7')
        c.add_task(orca.CoMTask, 'com')
        c.add_task(orca.JointAccelerationTask, 'posture')
        c.add_constraint(orca.JointTorqueLimitConstraint, 'torque')
        c.add_constraint(orca.JointPositionLimitConstraint, 'position')
        c.get_levels()
    qc = quadruped.QuadrupedController(quadruped.make_robot())
    qc.controller.get_levels()
    # the levels' kernels: typed by how many levels come below the first (one, two)
    for strategy, n in (('multi_level_weighted', 2), ('generalized', 3)):
        robot = orca.RobotModel()
        robot.load_model_from_file(orca.default_urdf_path())
        robot.set_robot_state(STACK_Q0, np.zeros(7))
        c = orca.Controller('warm', robot, strategy)
        add_conflicting_stack(c, n)
        add_standard_constraints(c)
        if strategy == 'generalized':
            c.set_priority('ee', 'elbow', 0.5)
        c.get_levels()
    assert np.isfinite(time.perf_counter() - t0)
    print(f'compiled-cycle kernels ready in {time.perf_counter() - t0:.1f} s')
    return 0


if __name__ == '__main__':
    sys.exit(main())
