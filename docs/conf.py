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
"""Sphinx configuration of orca_ros's documentation (rosdoc2 reads the same file)."""

import os
import re
import sys
import xml.etree.ElementTree as ElementTree


def _source_dir() -> str:
    """
    Return docs/ of the checkout.

    rosdoc2 runs this file's text from a conf.py of its own in a copy of docs/ (its "wrapped"
    directory), where the package is not next door; that wrapper names this file.
    """
    here = os.path.dirname(os.path.abspath(__file__))
    if os.path.isfile(os.path.join(here, '..', 'package.xml')):
        return here
    with open(os.path.join(here, 'conf.py')) as fh:
        m = re.search(r'exec\(open\("(.+?)"\)', fh.read())
    return os.path.dirname(m.group(1)) if m else here


HERE = _source_dir()
sys.path.insert(0, os.path.join(HERE, '_ext'))
sys.path.insert(0, os.path.dirname(HERE))  # the package, for autodoc and the generator
release = version = ElementTree.parse(os.path.join(HERE, '..', 'package.xml')).find('version').text

project = 'orca_ros'
author = 'orca_ros developers'
copyright = '2026, orca_ros developers'

extensions = ['myst_parser', 'sphinx.ext.autodoc', 'parameter_reference']
source_suffix = {'.md': 'markdown', '.rst': 'restructuredtext'}
exclude_patterns = ['_build']
myst_heading_anchors = 3
autodoc_typehints = 'none'
html_theme = 'alabaster'
html_static_path = []
