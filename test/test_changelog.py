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
CHANGELOG.rst in the ROS convention.

catkin_pkg (bloom's parser) reads it, and its newest version is package.xml's, with a date.
"""

import os

from catkin_pkg.changelog import get_changelog_from_path
from catkin_pkg.package import parse_package

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_changelog_parses_and_its_newest_version_is_the_package_version():
    package = parse_package(os.path.join(ROOT, 'package.xml'))
    changelog = get_changelog_from_path(os.path.join(ROOT, 'CHANGELOG.rst'), package.name)
    versions = [(version, date) for version, date, _ in changelog.foreach_version()]
    assert versions, 'no version section in CHANGELOG.rst'
    assert versions[0][0] == package.version
    assert versions[0][1] is not None  # a dated release header: "0.1.0 (YYYY-MM-DD)"
    with open(os.path.join(ROOT, 'CHANGELOG.rst')) as fh:
        head = fh.read().splitlines()[:3]
    assert head[1] == f'Changelog for package {package.name}'
    assert head[0] == head[2] == '^' * len(head[1])
