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
The live browser view's ROS-free parts.

:mod:`.robot_scene` (the URDF's visual geometry placed by a joint state, Pinocchio),
:mod:`.shapes` (primitives as triangle meshes), :mod:`.gizmos` (the target gizmos' bookkeeping:
frames, drags, who moved a target last) and :mod:`.page` (the page on viser, an optional
dependency). The node that feeds them from ROS is :mod:`orca_ros.ros.web_view`.
"""
