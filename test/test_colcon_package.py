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
Colcon builds the package like a ROS workspace would.

And a node starts exactly as `ros2 run` finds it.
"""

import os
import shutil
import subprocess
import sys
import time

import pytest

pytest.importorskip('rclpy')

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.fixture(scope='module')
def workspace(tmp_path_factory):
    ws = tmp_path_factory.mktemp('ws')
    src = ws / 'src' / 'orca_ros'
    shutil.copytree(
        ROOT,
        src,
        ignore=shutil.ignore_patterns(
            '.venv',
            '.venv-tsid',
            '.git',
            'build',
            'install',
            'log',
            'output',
            '__pycache__',
            '*.egg-info',
            '.pytest_cache',
        ),
    )
    colcon = os.path.join(os.path.dirname(sys.executable), 'colcon')
    # package selection (colcon-package-selection, pinned) as a ROS user types it
    proc = subprocess.run(
        [colcon, 'build', '--packages-select', 'orca_ros'],
        cwd=ws,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return ws


def test_colcon_install_layout(workspace):
    prefix = workspace / 'install' / 'orca_ros'
    for exe in ('orca_controller', 'pybullet_bridge', 'bag_recorder', 'plot', 'orca_main_job'):
        path = prefix / 'lib' / 'orca_ros' / exe
        assert path.is_file() and os.access(path, os.X_OK), f'missing executable {path}'
    assert (
        prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'orca_ros'
    ).is_file()
    assert (prefix / 'share' / 'orca_ros' / 'package.xml').is_file()
    assert (prefix / 'share' / 'orca_ros' / 'urdf' / 'lwr.urdf').is_file()
    assert (prefix / 'share' / 'orca_ros' / 'config' / 'lwr_controller.yaml').is_file()


def test_node_starts_as_ros2_run_finds_it(workspace, tmp_path):
    from ament_index_python.packages import get_package_prefix

    prefix = str(workspace / 'install' / 'orca_ros')
    env = dict(
        os.environ,
        AMENT_PREFIX_PATH=prefix,
        ROS_DOMAIN_ID='231',
        ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
    )
    site = [
        str(p) for p in (workspace / 'install' / 'orca_ros' / 'lib').glob('python3*/site-packages')
    ]
    env['PYTHONPATH'] = os.pathsep.join(site + [env.get('PYTHONPATH', '')])
    old = os.environ.get('AMENT_PREFIX_PATH')
    os.environ['AMENT_PREFIX_PATH'] = prefix
    try:
        found = get_package_prefix('orca_ros')  # what `ros2 run orca_ros <exe>` looks up
    finally:
        if old is None:
            del os.environ['AMENT_PREFIX_PATH']
        else:
            os.environ['AMENT_PREFIX_PATH'] = old
    exe = os.path.join(found, 'lib', 'orca_ros', 'orca_controller')
    cfg = os.path.join(found, 'share', 'orca_ros', 'config', 'lwr_controller.yaml')
    log = open(tmp_path / 'node.log', 'w')
    p = subprocess.Popen(
        [exe, '--ros-args', '--params-file', cfg],
        env=env,
        stdout=log,
        stderr=subprocess.STDOUT,
        cwd=str(tmp_path),
    )
    try:
        t0 = time.time()
        text = ''
        while time.time() - t0 < 30 and 'orca_controller: 7 joints' not in text:
            time.sleep(0.2)
            text = (tmp_path / 'node.log').read_text()
        assert 'orca_controller: 7 joints' in text, text[-3000:]
        assert p.poll() is None
        # the installed package (not the source tree) provided the module
        assert (
            str(workspace / 'install')
            in subprocess.run(
                [sys.executable, '-c', 'import orca_ros; print(orca_ros.__file__)'],
                env=env,
                capture_output=True,
                text=True,
                cwd=str(tmp_path),
            ).stdout
        )
    finally:
        p.terminate()
        p.wait(timeout=10)
        log.close()
