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
"""The ``mujoco_bridge`` node: the simulator bridge on MuJoCo, and its console script."""

import sys

from .common import run_node
from .sim_bridge import SimBridge
from ..utils.optional_import import MissingDependency, optional_import


class MujocoBridge(SimBridge):
    SIMULATOR = 'mujoco'


def main(args=None) -> int:
    try:
        optional_import('mujoco', 'mujoco_bridge')
    except MissingDependency as exc:
        print(exc, file=sys.stderr)
        return 1
    return run_node(MujocoBridge, args, on_shutdown=None)


if __name__ == '__main__':
    sys.exit(main())
