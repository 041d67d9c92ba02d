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
URDF text made loadable by any reader: file names resolved, collision shapes swapped.

PyBullet does not know ROS packages: a description such as example-robot-data's Talos names
its meshes ``package://example-robot-data/...`` and PyBullet loads it without them. And a dynamic
body's collision mesh becomes its convex hull in PyBullet, whose contact with the ground can be
poor: Talos standing on the hulls of its ankle meshes is soon thrown off the ground, on
boxes of its soles' size it stands (``test/test_talos_pybullet.py``). Both are edits of the URDF
text, made here with the standard library's XML parser.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

_SCHEME = 'package://'
_FILE = 'file://'


def package_directory(package: str, urdf_path: str, package_dirs=None) -> str | None:
    """
    Directory of ROS package ``package`` for the URDF at ``urdf_path``.

    ``package_dirs`` ({name: directory}) first; else the nearest parent directory of the URDF
    named after the package (a package's share directory holds its URDF files); else a directory
    of that name beside the URDF (PyBullet's reading: pybullet_data's Panda names its meshes
    ``package://meshes/...``, its ``meshes`` directory beside the file).
    """
    if package_dirs and package in package_dirs:
        return os.path.abspath(package_dirs[package])
    here = d = os.path.dirname(os.path.abspath(urdf_path))
    while True:
        if os.path.basename(d) == package:
            return d
        parent = os.path.dirname(d)
        if parent == d:
            beside = os.path.join(here, package)
            return beside if os.path.isdir(beside) else None
        d = parent


def resolve_package_uris(text: str, urdf_path: str, package_dirs=None) -> str:
    """
    Replace every file name the URDF gives (meshes, textures) by an absolute path.

    ``package://name/rest``: in the package's directory (:func:`package_directory`);
    ``file://path`` and a bare path: as they are when absolute, else relative to the URDF's own
    directory (``urdf_path``; a URDF given as text only, ``urdf_path`` empty, keeps a relative
    name, which then means the working directory, as for any program reading it). URDF readers
    differ here (PyBullet reads a bare name relative to the URDF, Pinocchio and coal relative to
    the working directory), so the name is made absolute once for all of them: pybullet_data's
    iiwa names its meshes ``meshes/link_0.stl``.

    Raises ValueError naming a package that cannot be found.
    """
    root = ET.fromstring(text)
    here = os.path.dirname(os.path.abspath(urdf_path)) if urdf_path else None
    for element in root.iter():  # meshes, and the textures of materials
        name = element.get('filename', '')
        if not name:
            continue
        if name.startswith(_SCHEME):
            package, _, rest = name[len(_SCHEME):].partition('/')
            base = package_directory(package, urdf_path, package_dirs)
            if base is None:
                raise ValueError(
                    f"URDF '{urdf_path}': package '{package}' not found (pass package_dirs)"
                )
            element.set('filename', os.path.join(base, rest))
            continue
        path = name[len(_FILE):] if name.startswith(_FILE) else name
        if '://' in path:  # another scheme (http://...): left to the reader
            continue
        if not os.path.isabs(path) and here is not None:
            path = os.path.join(here, path)
        element.set('filename', path)
    return ET.tostring(root, encoding='unicode')


def replace_collisions_with_boxes(text: str, boxes: dict) -> str:
    """
    Give each named link one box as its collision shape.

    ``boxes``: {link name: (size (3,), centre (3,) in the link frame)}. Raises ValueError for a
    link the URDF does not have.
    """
    root = ET.fromstring(text)
    links = {ln.get('name'): ln for ln in root.findall('link')}
    for name, (size, centre) in boxes.items():
        if name not in links:
            raise ValueError(f"URDF has no link '{name}'")
        link = links[name]
        for old in link.findall('collision'):
            link.remove(old)
        col = ET.SubElement(link, 'collision')
        ET.SubElement(col, 'origin', xyz=_vec(centre), rpy='0 0 0')
        geo = ET.SubElement(col, 'geometry')
        ET.SubElement(geo, 'box', size=_vec(size))
    return ET.tostring(root, encoding='unicode')


def _vec(values) -> str:
    v = [float(x) for x in values]
    if len(v) != 3:
        raise ValueError(f'expected 3 values, got {len(v)}')
    return ' '.join(repr(x) for x in v)
