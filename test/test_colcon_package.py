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
Colcon builds the package like a ROS workspace would: the README's ROS 2 route, as written.

``colcon build`` runs as the README writes it; ``source install/setup.bash`` then ``ros2 run``
(ros2cli is not on PyPI: its lookup is done here with ament_index, as ``ros2 run`` does it) start
the node with the README's arguments, from the workspace.
"""

import os
import shlex
import shutil
import subprocess
import sys
import time

import pytest
from readme_blocks import ros_route

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
    argv = ros_route()['colcon']
    assert argv[:2] == ['colcon', 'build']
    colcon = os.path.join(os.path.dirname(sys.executable), 'colcon')
    # package selection (colcon-package-selection, pinned) as a ROS user types it
    proc = subprocess.run(
        [colcon, *argv[1:]],
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
    assert (prefix / 'share' / 'orca_ros' / 'mjcf' / 'lwr.xml').is_file()
    assert (prefix / 'share' / 'orca_ros' / 'config' / 'lwr_controller.yaml').is_file()


# ``ros2 run PKG EXE ARGS``: the package's prefix from the ament index, then lib/PKG/EXE
ROS2_RUN = """
import os, sys
from ament_index_python.packages import get_package_prefix
pkg, exe, *args = sys.argv[1:]
path = os.path.join(get_package_prefix(pkg), 'lib', pkg, exe)
os.execv(path, [path, *args])
"""


def test_node_starts_as_the_readme_runs_it(workspace, tmp_path):
    route = ros_route()
    assert route['source'] == ['source', 'install/setup.bash']
    assert route['ros2'][:2] == ['ros2', 'run']
    (tmp_path / 'ros2_run.py').write_text(ROS2_RUN)
    env = dict(os.environ, ROS_DOMAIN_ID='231', ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.pop('AMENT_PREFIX_PATH', None)
    env.pop('PYTHONPATH', None)
    setup = ' '.join(route['source'])
    run = ' '.join(shlex.quote(a) for a in route['ros2'][2:])
    log = open(tmp_path / 'node.log', 'w')
    p = subprocess.Popen(
        ['bash', '-c', f"{setup} && exec {sys.executable} {tmp_path / 'ros2_run.py'} {run}"],
        env=env,
        stdout=log,
        stderr=subprocess.STDOUT,
        cwd=str(workspace),
    )
    try:
        # the installed copy's kernels compile at its first start (their disk cache is keyed by
        # the installed files): ~30 s idle, minutes on a loaded 2-core machine (2 CPU burners
        # beside the suite: more than 60 s). Wait while the node runs; it ends only on an error
        t0 = time.time()
        text = ''
        while (time.time() - t0 < 900 and p.poll() is None
               and 'orca_controller: 7 joints' not in text):
            time.sleep(0.2)
            text = (tmp_path / 'node.log').read_text()
        assert 'orca_controller: 7 joints' in text, text[-3000:]
        assert 'solver daqp' in text
        assert p.poll() is None
        # the installed package (not the source tree) provided the module
        which = f'{sys.executable} -c "import orca_ros; print(orca_ros.__file__)"'
        where = subprocess.run(
            ['bash', '-c', f'{setup} && {which}'],
            env=env,
            capture_output=True,
            text=True,
            cwd=str(workspace),
        ).stdout
        assert str(workspace / 'install') in where, where
    finally:
        p.terminate()
        try:
            p.wait(timeout=30)
        except subprocess.TimeoutExpired:  # still compiling: a signal waits for the compiler
            p.kill()
            p.wait(timeout=30)
        log.close()
