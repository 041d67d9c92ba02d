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
Simulating multiple robots.

Two arms side by side in one world, each put in its own configuration (the reference's "set robot
state" too); the first is held by gravity compensation, the second is left unpowered and falls, and
each model reports only its own joints. Any arm's URDF: the postures are the lwr's clipped into
its joint limits (see ``arm``).
"""

from __future__ import annotations

import sys

import numpy as np

from .arm import posture
from .sim_common import parse_sim_args
from .. import RobotModel
from ..sim import SimServer


def run(urdf: str, duration: float = 1.0, gui: bool = False):
    robot = RobotModel()
    robot.load_model_from_file(urdf)
    with SimServer(gui=gui) as server:
        left = server.insert_model_from_urdf_file(urdf, position=(0.0, -0.6, 0.0), name='left')
        right = server.insert_model_from_urdf_file(urdf, position=(0.0, 0.6, 0.0), name='right')
        q_left = posture(robot, [0.2, 0.6, 0.0, -1.0, 0.0, 0.5, 0.0])
        q_right = posture(robot, [-0.2, 0.4, 0.3, -0.8, 0.0, 0.4, 0.0])
        names = robot.get_joint_names()  # arrays below are in this (Pinocchio's) order
        left.set_model_configuration(names, q_left)
        right.set_model_configuration(names, q_right)
        set_ok = np.allclose(left.get_joint_positions(names), q_left) and np.allclose(
            right.get_joint_positions(names), q_right
        )
        on_left = left.joint_map(names)

        def hold_left(n, t, dt):
            robot.set_robot_state(
                left.get_joint_positions(on_left), left.get_joint_velocities(on_left)
            )
            left.set_joint_gravity_torques(on_left.to_sim(robot.get_joint_gravity_torques()))

        hold_left(0, 0.0, server.time_step)
        left.execute_after_world_update(hold_left)
        server.run(duration)
        return {
            'set_ok': set_ok,
            'left_moved': float(np.abs(left.get_joint_positions(names) - q_left).max()),
            'right_moved': float(np.abs(right.get_joint_positions(names) - q_right).max()),
            'bases': (
                left.get_world_to_base_transform()[:3, 3],
                right.get_world_to_base_transform()[:3, 3],
            ),
        }


def main(argv=None) -> int:
    args = parse_sim_args(__doc__, argv)
    res = run(args.urdf, args.duration, args.gui)
    print(f"configurations set: {res['set_ok']}; bases at {res['bases'][0]} and {res['bases'][1]}")
    print(
        f"held arm moved {res['left_moved']:.2e} rad, unpowered arm moved "
        f"{res['right_moved']:.2f} rad"
    )
    return 0 if res['set_ok'] and res['left_moved'] < 1e-6 and res['right_moved'] > 0.05 else 1


if __name__ == '__main__':
    sys.exit(main())
