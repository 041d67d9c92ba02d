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
Fill the compiled cycle's disk cache ahead of time: ``python -m orca_ros.warm``.

The kernels are compiled for the types of a configuration (fixed or floating base, contacts or
none, a centre-of-mass task, one or two strict or generalized levels below the first), once per
kind, and a later process loads them instead of compiling them (several times longer). This
builds, through the public API, a controller of each kind: the shipped configurations as they
are (``config/lwr_controller.yaml``, two strict levels; ``config/quadruped_controller.yaml``, a
floating base on four contacts) and variants of the arm's (one weighted level with a CoM task on
a fixed and on a floating base; three generalized levels). The test command runs it first, so
that no test's timing includes a cold compile (test_compiled_startup.py measures one on
purpose, in a folder of its own).
"""

from __future__ import annotations

import copy
import sys
import time


def _shipped(name: str) -> dict:
    """Return the controller parameters of ``config/<name>_controller.yaml``."""
    import yaml  # noqa: PLC0415

    from orca_ros import share_path  # noqa: PLC0415

    with open(share_path('config', f'{name}_controller.yaml')) as fh:
        return yaml.safe_load(fh)['orca_controller']['ros__parameters']


def _variants(arm: dict):
    """Yield the arm's configuration as one weighted level with a CoM task, and as three levels."""
    for floating in (False, True):
        cfg = copy.deepcopy(arm)
        cfg.update(floating_base=floating, base_frame='world',
                   resolution_strategy='one_level_weighted')
        cfg['tasks']['names'].append('com')
        cfg['tasks']['com'] = {'type': 'com', 'weight': 1e-2, 'kp': 10.0, 'kd': 5.0}
        yield cfg
    cfg = copy.deepcopy(arm)
    cfg['resolution_strategy'] = 'generalized'
    tasks = cfg['tasks']
    tasks['names'].insert(1, 'elbow')
    tasks['elbow'] = {'type': 'cartesian', 'frame': 'link_4', 'kp': 100.0, 'kd': 20.0,
                      'selection': [1, 1, 1, 0, 0, 0], 'level': 1, 'active': True}
    tasks['posture']['level'] = 2
    tasks['ee']['priority_over'] = {'elbow': 0.5}
    yield cfg


def main() -> int:
    import numpy as np  # noqa: PLC0415

    from orca_ros.configuration import build_from_config  # noqa: PLC0415

    t0 = time.perf_counter()
    arm = _shipped('lwr')
    for cfg in (arm, _shipped('quadruped'), *_variants(arm)):
        setup = build_from_config(cfg)
        robot = setup.robot
        if not robot.is_floating_base():
            robot.set_robot_state(np.array(arm['tasks']['posture']['target']), np.zeros(7))
        setup.controller.get_levels()  # configuration: the kernels compile or load here
    print(f'compiled-cycle kernels ready in {time.perf_counter() - t0:.1f} s')
    return 0


if __name__ == '__main__':
    sys.exit(main())
