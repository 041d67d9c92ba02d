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
"""The ament copyright linter: every source file carries the Apache-2.0 notice."""

import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHECKED = ['orca_ros', 'test', 'bench', 'scripts', 'tools', 'setup.py', 'LICENSE',
           'CONTRIBUTING.md']


@pytest.mark.copyright
@pytest.mark.linter
def test_copyright():
    try:
        from ament_copyright.main import main
    except ImportError:
        pytest.fail(
            'ament_copyright is missing: scripts/debian_python_tools.py installs it from '
            "Debian's archive (it is not on PyPI); was deb.debian.org reachable?"
        )
    rc = main(argv=[os.path.join(ROOT, p) for p in CHECKED])
    assert rc == 0, 'files without the copyright notice or license (see above)'
