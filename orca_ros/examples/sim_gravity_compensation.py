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
Set robot state with gravity compensation.

The arm is put in a configuration and held there by the torques g(q) from the core's RobotModel
(emulating drives with built-in gravity compensation), so it stays still; then the same without
compensation falls. Any arm's URDF: its start posture is the lwr's clipped into its joint limits
(see ``arm``).
"""

from __future__ import annotations

import sys

import numpy as np

from .arm import posture
from .sim_common import parse_sim_args
from .. import RobotModel
from ..sim import SimServer


def run(urdf: str, duration: float = 2.0, gui: bool = False, compensate: bool = True):
    robot = RobotModel()
    robot.load_model_from_file(urdf)
    with SimServer(gui=gui) as server:
        model = server.insert_model_from_urdf_file(urdf)
        q0 = posture(robot, [0.4, 0.8, -0.3, -1.1, 0.5, 0.7, 0.1])
        by_name = model.joint_map(robot.get_joint_names())  # the simulator's order may differ
        model.set_model_configuration(by_name.names, q0)

        def compensate_gravity(n, t, dt):
            robot.set_robot_state(
                model.get_joint_positions(by_name), model.get_joint_velocities(by_name)
            )
            g = robot.get_joint_gravity_torques() if compensate else np.zeros(q0.size)
            model.set_joint_gravity_torques(by_name.to_sim(g))

        compensate_gravity(0, 0.0, server.time_step)
        model.execute_after_world_update(compensate_gravity)
        server.run(duration)
        return {
            'q0': q0,
            'q': model.get_joint_positions(by_name),
            'measured': model.get_joint_measured_torques(by_name),
        }


def main(argv=None) -> int:
    args = parse_sim_args(__doc__, argv)
    held = run(args.urdf, args.duration, args.gui, True)
    fell = run(args.urdf, args.duration, args.gui, False)
    d_held = np.abs(held['q'] - held['q0']).max()
    d_fell = np.abs(fell['q'] - fell['q0']).max()
    print(f'with gravity compensation the arm moved {d_held:.2e} rad; without, {d_fell:.2f} rad')
    return 0 if d_held < 1e-6 and d_fell > 0.1 else 1


if __name__ == '__main__':
    sys.exit(main())
