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
Import a dependency that has no rosdep key, or say how to install it.

Under an apt-installed ROS 2, packages without a rosdep key (osqp, daqp, ruckig's Python bindings,
pybullet) come from pip; a missing one must fail with the pip line, not an anonymous ImportError.
"""

import importlib

# the versions the project is tested with (requirements.txt)
PIP = {
    'osqp': 'osqp==1.1.3',
    'daqp': 'daqp==0.11.0',
    'proxsuite': 'proxsuite==0.8.0',
    'ruckig': 'ruckig==0.19.4',
    'pybullet': 'pybullet==3.2.7',
    'rosbags': 'rosbags==0.11.9',
    'numba': 'numba==0.68.1',
    'viser': 'viser==1.1.1',
    'mujoco': 'mujoco==4.0.0',
    'mujoco_menagerie': 'mujoco-menagerie==2026.10.4',
}


class MissingDependency(ImportError):
    pass


def optional_import(name: str, purpose: str, alternative: str = ''):
    """Import name; when it is missing, raise MissingDependency naming the pip package."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        hint = f' ({alternative})' if alternative else ''
        top = name.split('.')[0]
        raise MissingDependency(
            f"{purpose} needs the Python package '{top}': pip install {PIP.get(top, top)}{hint}"
        ) from exc
