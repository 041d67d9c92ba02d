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
Every file, test or benchmark that the README and the code cite exists in the repository.

Scanned: README.md, the Python files under orca_ros/, bench/ and test/, config/ and docs/ (when
present). A citation is a repository path of one of the forms checked below (a benchmark or test
script, a module of the package, a shipped configuration, a script, a URDF), or a test module's
bare file name, which resolves under test/. A path that is part of a longer one (another
package's urdf/ folder, a share/ directory) is not a citation of this repository; names with
wildcards or format fields are patterns, not citations; a test module's name joined to another
folder (``tmp_path / 'test_x.py'``) is a file a test makes, not a citation.
"""

from __future__ import annotations

import glob
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# not preceded by a path character: the start of a repository-relative path
_START = r'(?<![\w./\\-])'
_END = r'(?![\w-])'
_FORMS = [
    _START + r'(?:bench|test|orca_ros)/\w[\w./-]*?\.py' + _END,
    _START + r'config/\w[\w./-]*?\.yaml' + _END,
    _START + r'(?:scripts|urdf)/\w[\w./-]*',
    # a bare test module name, unless joined to a folder (``tmp_path / 'test_x.py'``: a file
    # a test makes elsewhere)
    _START + r"(?<!/ ')" + r'test_\w+\.py' + _END,
]
CITATION = re.compile('|'.join(f'(?:{f})' for f in _FORMS))


def scanned_files() -> list[str]:
    out = [os.path.join(ROOT, 'README.md')]
    for pattern in ('orca_ros/**/*.py', 'bench/**/*.py', 'test/**/*.py', 'config/*', 'docs/**/*'):
        out += glob.glob(os.path.join(ROOT, pattern), recursive=True)
    return sorted(p for p in set(out) if os.path.isfile(p))


def citations(text: str) -> list[tuple[int, str]]:
    """(line number, path relative to the repository) of each citation in ``text``."""
    found = []
    for n, line in enumerate(text.splitlines(), 1):
        for m in CITATION.finditer(line):
            path = m.group(0).rstrip('.')
            if '/' not in path:  # a test module's bare name
                path = 'test/' + path
            found.append((n, path))
    return found


def test_the_scanner_finds_each_form_and_skips_foreign_paths():
    text = (
        'see bench/bench_tsid.py, test/test_qp.py and test_qp.py; config/lwr_controller.yaml,\n'
        'scripts/run_tests.sh. urdf/lwr.urdf; orca_ros/paths.py\n'
        "not: panda_description/urdf/panda.urdf, <share>/orca_ros/config/x.yaml, 'test_{n}.py',\n"
        "test_ros_*.py, the urdf/ folder, mytest_a.py, tmp_path / 'test_made_here.py'"
    )
    assert [p for _, p in citations(text)] == [
        'bench/bench_tsid.py',
        'test/test_qp.py',
        'test/test_qp.py',
        'config/lwr_controller.yaml',
        'scripts/run_tests.sh',
        'urdf/lwr.urdf',
        'orca_ros/paths.py',
    ]


def test_every_cited_file_exists():
    missing = []
    checked = 0
    for path in scanned_files():
        with open(path, encoding='utf-8', errors='replace') as fh:
            text = fh.read()
        for line, cited in citations(text):
            checked += 1
            if not os.path.exists(os.path.join(ROOT, cited)):
                missing.append(f'{os.path.relpath(path, ROOT)}:{line}: {cited}')
    assert checked > 50, f'only {checked} citations found: is the scanner broken?'
    assert not missing, 'citations of files that do not exist:\n' + '\n'.join(missing)
