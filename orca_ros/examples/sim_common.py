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
"""Shared pieces of the simulator examples (the reference's Gazebo examples, on PyBullet)."""

from __future__ import annotations

import argparse

from .. import default_urdf_path, Logger


def parse_sim_args(description: str, argv=None, extra=None):
    rest = Logger.parse_argv(argv)
    p = argparse.ArgumentParser(description=description)
    p.add_argument(
        'urdf', nargs='?', default=None, help='robot URDF (default: the shipped lwr.urdf)'
    )
    p.add_argument('--gui', action='store_true', help='show the PyBullet window')
    p.add_argument('--duration', type=float, default=2.0, help='simulated seconds')
    if extra is not None:
        extra(p)
    args = p.parse_args(rest)
    args.urdf = args.urdf or default_urdf_path()
    return args
