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
"""Dependencies without a rosdep key fail with the pip line, pinned as in requirements.txt."""

import os
import re

from orca_ros.utils.optional_import import MissingDependency, optional_import, PIP
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_missing_dependency_names_the_pip_package(monkeypatch):
    monkeypatch.setitem(PIP, 'no_such_solver_pkg', 'no_such_solver_pkg==1.2.3')
    with pytest.raises(MissingDependency) as exc:
        optional_import('no_such_solver_pkg', "solver 'x'", 'or solver: daqp')
    assert str(exc.value) == (
        "solver 'x' needs the Python package 'no_such_solver_pkg': "
        'pip install no_such_solver_pkg==1.2.3 (or solver: daqp)'
    )


def test_pip_hints_match_the_pinned_requirements():
    with open(os.path.join(ROOT, 'requirements.txt')) as fh:
        pins = dict(re.findall(r'^([A-Za-z0-9_.-]+)==(\S+)', fh.read(), re.M))
    for spec in PIP.values():
        name, version = spec.split('==')
        assert pins.get(name) == version, f'{spec} is not the pinned {name}=={pins.get(name)}'


def test_package_xml_names_only_existing_rosdep_keys():
    with open(os.path.join(ROOT, 'package.xml')) as fh:
        xml = fh.read()
    # no such keys in rosdistro's rosdep/python.yaml (checked 2026-11): pip only, optional at
    # run time
    for key in ('python3-osqp-pip', 'python3-daqp-pip', 'python3-ruckig-pip'):
        assert key not in xml
    assert '<license>Apache-2.0</license>' in xml
