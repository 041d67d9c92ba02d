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
"""Where the package's data (URDFs, YAML configs) lives: source tree, pip install or ROS share/."""

from __future__ import annotations

import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))


def share_path(*parts: str) -> str:
    """
    Path of a file shipped under ``urdf/``, ``mjcf/`` or ``config/``.

    Looked up in the source checkout first, then in ``<prefix>/share/orca_ros`` (colcon / pip data
    files).
    """
    candidates = [
        os.path.join(os.path.dirname(_HERE), *parts),
        os.path.join(sys.prefix, 'share', 'orca_ros', *parts),
    ]
    try:  # a ROS install: the ament index knows the share directory
        from ament_index_python.packages import get_package_share_directory  # noqa: PLC0415

        candidates.append(os.path.join(get_package_share_directory('orca_ros'), *parts))
    except Exception:
        pass
    for c in candidates:
        if os.path.exists(c):
            return c
    raise FileNotFoundError(
        f"shipped file {'/'.join(parts)} not found (looked in: {', '.join(candidates)})"
    )


def default_urdf_path() -> str:
    """Return the path of the 7-DoF arm shipped with the package."""
    return share_path('urdf', 'lwr.urdf')
