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
A collision avoidance constraint from its configuration (``type: collision_avoidance``).

    collision:
      type: collision_avoidance
      srdf: panda.srdf            # optional: its disable_collisions pairs are left out
      influence_distance: 0.1     # m
      safety_distance: 0.02       # m
      max_pairs: 16
      max_deceleration: 5.0       # m/s^2
      horizon: 0.1                # s
      max_extrapolation: 0.1      # s: a moving obstacle's pose carried on (its poses' period
                                  # plus latency: a 10 Hz perception, 0.2)
      pair_samples: 10000         # postures sampled: self pairs never or always in contact
                                  # are left out (0: none; python -m
                                  # orca_ros.robot.collision_pairs URDF writes them as an SRDF)
      max_depth: 0.1              # m: an obstacle added or moved deeper into the robot's moving
                                  # bodies is refused (ValueError; the node logs it)
      obstacles: [table]          # names, each described below
      table: {shape: box, size: [1.0, 1.0, 0.05], position: [0.5, 0.0, 0.0], rpy: [0, 0, 0],
              frame: world}       # frame: world (default), or a link the obstacle moves with

An SRDF path that is not found as given is looked up next to the URDF, then in the package's
``urdf/`` directory.
"""

from __future__ import annotations

import os

import numpy as np

from .config_error import ConfigError
from ..constraint.collision_avoidance import CollisionAvoidanceConstraint
from ..math.rotations import make_transform, rotation_from_rpy
from ..paths import share_path

_SETTINGS = ('influence_distance', 'safety_distance', 'max_pairs', 'max_deceleration', 'horizon',
             'max_extrapolation', 'pair_samples', 'max_depth')


def _srdf_path(path: str, urdf_path: str | None) -> str:
    candidates = [path]
    if urdf_path:
        candidates.append(os.path.join(os.path.dirname(urdf_path), path))
    for c in candidates:
        if os.path.isfile(c):
            return c
    try:
        return share_path('urdf', path)
    except FileNotFoundError:
        raise ConfigError(f"SRDF '{path}' not found (as given, next to the URDF, nor in the "
                          "package's urdf/ directory)") from None


def make_collision_avoidance(name: str, cc: dict, robot) -> CollisionAvoidanceConstraint:
    kwargs = {}
    for key in _SETTINGS:
        if key in cc:
            try:
                whole = key in ('max_pairs', 'pair_samples')
                kwargs[key] = int(cc[key]) if whole else float(cc[key])
            except (TypeError, ValueError):
                raise ConfigError(f"constraint '{name}': {key} must be a number") from None
    srdf = _srdf_path(str(cc['srdf']), robot.urdf_path) if cc.get('srdf') else None
    try:
        c = CollisionAvoidanceConstraint(name, srdf=srdf, **kwargs)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    for obstacle in cc.get('obstacles') or []:
        oc = cc.get(obstacle)
        if not isinstance(oc, dict):
            raise ConfigError(f"constraint '{name}': obstacle '{obstacle}' is not described")
        try:
            pos = np.asarray(oc.get('position', [0.0, 0.0, 0.0]), dtype=float).reshape(3)
            rpy = np.asarray(oc.get('rpy', [0.0, 0.0, 0.0]), dtype=float).reshape(3)
            pose = make_transform(pos, rotation_from_rpy(*rpy))
            c.add_obstacle(obstacle, str(oc.get('shape', '')), oc.get('size'), pose,
                           oc.get('frame'))
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"constraint '{name}': obstacle '{obstacle}': {exc}") from None
    return c
