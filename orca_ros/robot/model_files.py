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
A robot's Pinocchio model from its description: URDF text, or a URDF or MJCF file.

The root element tells the formats apart. URDF: Pinocchio's parser, a free-flyer root joint for a
floating base. MJCF: :mod:`.mjcf` (Pinocchio's parser, the root body placed as the file says, the
actuators' torque limits). Every refusal is a ValueError (FileNotFoundError for a missing file)
naming what the parser refused.
"""

from __future__ import annotations

import os
from typing import NamedTuple

import pinocchio as pin

from .mjcf import build_mjcf_model, is_mjcf


class ModelSource(NamedTuple):
    """A parsed model and where it came from (the collision geometry reads its description)."""

    model: pin.Model
    urdf_path: str | None
    urdf_xml: str | None
    mjcf_path: str | None


def model_from_urdf_text(urdf_xml: str, floating_base: bool) -> pin.Model:
    """Parse URDF text (MJCF text is refused: its meshes and includes need its directory)."""
    if isinstance(urdf_xml, str) and is_mjcf(urdf_xml):
        raise ValueError('MJCF text: give its file (its meshes and includes are found from '
                         'its directory)')
    if not isinstance(urdf_xml, str) or '<robot' not in urdf_xml:
        raise ValueError('not a URDF description: no <robot> element in the given string')
    try:
        if floating_base:
            return pin.buildModelFromXML(urdf_xml, pin.JointModelFreeFlyer())
        return pin.buildModelFromXML(urdf_xml)
    except Exception as exc:  # pinocchio raises ValueError/RuntimeError with its own text
        raise ValueError(f'could not parse URDF: {exc}') from exc


def model_from_file(path, floating_base: bool) -> ModelSource:
    """Parse a URDF or MJCF file (told apart by the root element)."""
    if not isinstance(path, (str, os.PathLike)) or not os.path.isfile(path):
        raise FileNotFoundError(f"robot model file not found: '{path}'")
    with open(path, 'r', encoding='utf-8') as fh:
        xml = fh.read()
    path = os.fspath(path)
    if is_mjcf(xml):
        return ModelSource(build_mjcf_model(path, floating_base), None, None, path)
    return ModelSource(model_from_urdf_text(xml, floating_base), path, xml, None)
