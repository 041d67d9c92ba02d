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
Simulated robot hardware (no ROS): PyBullet (``SimServer``, ``SimModel``) and MuJoCo.

MuJoCo's world keeps the same contract: ``orca_ros.sim.mujoco_server.MujocoServer`` and the
robots it inserts, ``orca_ros.sim.mujoco_model.MujocoModel`` (imported from their modules, so that
the PyBullet world needs no MuJoCo).
"""

from .base_hold import BaseHold
from .contacts import ContactPoint
from .joint_map import JointMap
from .sim_model import SimModel
from .sim_server import SimServer
from ..robot.urdf_text import replace_collisions_with_boxes, resolve_package_uris

__all__ = [
    'BaseHold',
    'ContactPoint',
    'JointMap',
    'replace_collisions_with_boxes',
    'resolve_package_uris',
    'SimModel',
    'SimServer',
]
