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
A missing optional part is reported, never dropped silently (conftest's OPTIONAL_GROUPS).

The suite's conftest runs in a pytest of its own on a few stand-in test files, with an rclpy that
does not import (a broken install) first on the path.
"""

import os
import shutil
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))


@pytest.fixture
def suite(tmp_path):
    """Run pytest on stand-ins of a core test and two ROS test files: (returncode, output)."""
    shutil.copy(os.path.join(HERE, 'conftest.py'), tmp_path / 'conftest.py')
    (tmp_path / 'test_core.py').write_text('def test_core():\n    assert 1 + 1 == 2\n')
    for name in ('test_ros_nodes.py', 'test_colcon_package.py'):
        (tmp_path / name).write_text('import rclpy\n\n\ndef test_node():\n    assert rclpy\n')
    broken = tmp_path / 'site' / 'rclpy'
    broken.mkdir(parents=True)
    (broken / '__init__.py').write_text(
        "raise ImportError('librcl.so: cannot open shared object file')\n"
    )

    def run(ci: str, broken_rclpy: bool = True):
        env = {k: v for k, v in os.environ.items() if k != 'CI'}
        env['CI'] = ci
        if broken_rclpy:
            env['PYTHONPATH'] = os.pathsep.join(
                [str(tmp_path / 'site')] + [p for p in [env.get('PYTHONPATH')] if p]
            )
        proc = subprocess.run(
            [sys.executable, '-m', 'pytest', '-q', '-rs', '-p', 'no:cacheprovider',
             '--rootdir', str(tmp_path), str(tmp_path)],
            capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300,
        )
        return proc.returncode, proc.stdout + proc.stderr

    return run


def test_a_broken_rclpy_is_reported_as_skipped_files_with_the_reason(suite):
    rc, out = suite('false')
    assert rc == 0, out
    assert '1 passed, 2 skipped' in out, out
    reason = ('optional part missing: ROS 2 nodes (import rclpy: ImportError: librcl.so: cannot '
              'open shared object file)')
    # one skip line per file (-rs) and a summary line naming the files
    assert out.count(reason) == 3, out
    assert 'SKIPPED 2 test files (test_colcon_package.py, test_ros_nodes.py)' in out, out


def test_under_ci_a_skipped_group_fails_the_run(suite):
    rc, out = suite('true')
    assert rc == 1, out
    assert '1 passed, 2 skipped' in out, out
    assert 'FAILED: CI=true and a whole group of tests was skipped' in out, out


def test_with_every_part_installed_nothing_is_skipped_under_ci(suite):
    rc, out = suite('true', broken_rclpy=False)
    assert rc == 0, out
    assert '3 passed' in out and 'skipped' not in out.lower(), out
