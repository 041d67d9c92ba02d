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
Simulating a single robot.

The arm is loaded in PyBullet with no command and falls under gravity; the after-step callback
prints its joint positions. Any arm's URDF: its start posture is the lwr's clipped into its joint
limits (see ``arm``).
"""

from __future__ import annotations

import sys

import numpy as np

from .arm import posture
from .sim_common import parse_sim_args
from .. import RobotModel
from ..sim import SimServer


def run(urdf: str, duration: float = 2.0, gui: bool = False):
    robot = RobotModel()
    robot.load_model_from_file(urdf)
    with SimServer(gui=gui) as server:
        model = server.insert_model_from_urdf_file(urdf, name='arm')
        q0 = posture(robot, [0.0, 0.3, 0.0, -0.3, 0.0, 0.2, 0.0])
        by_name = model.joint_map(robot.get_joint_names())  # the simulator's order may differ
        model.set_model_configuration(by_name.names, q0)
        log = []

        def every_100th(n, t, dt):
            if n % 100 == 0:
                log.append(model.get_joint_positions(by_name))

        model.execute_after_world_update(every_100th)
        server.run(duration)
        return {'q0': q0, 'q': model.get_joint_positions(by_name), 'log': np.array(log)}


def main(argv=None) -> int:
    args = parse_sim_args(__doc__, argv)
    res = run(args.urdf, args.duration, args.gui)
    for q in res['log']:
        print(np.round(q, 3))
    moved = np.abs(res['q'] - res['q0']).max()
    print(f'largest joint displacement without command: {moved:.3f} rad')
    return 0 if moved > 0.1 else 1  # unpowered, the arm must fall


if __name__ == '__main__':
    sys.exit(main())
