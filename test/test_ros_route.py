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
The README's ROS 2 route (rosdep, pip, colcon, ros2 run) against what the package needs.

``colcon build`` and ``ros2 run`` are run as the README writes them by test_colcon_package.py.
``rosdep install`` needs rosdistro's index, out of reach here: its input is checked instead, i.e.
every third-party module the package imports is covered by a key of package.xml (as catkin_pkg,
rosdep's parser, reads it) or by the README's pip line, and nothing else is on that line.
"""

import ast
import glob
import os
import re
import subprocess
import sys

from catkin_pkg.package import parse_package
from orca_ros.optim.solvers.availability import MODULE
from orca_ros.utils.optional_import import PIP
from readme_blocks import ROOT, ros_route

# the rosdep key (or 'pip' for the README's pip line) of every module the package imports
KEY_OF_MODULE = {
    'numpy': 'python3-numpy',
    'scipy': 'python3-scipy',
    'yaml': 'python3-yaml',
    'matplotlib': 'python3-matplotlib',
    'pinocchio': 'pinocchio',
    'coal': 'coal',
    'proxsuite': 'proxsuite',
    'numba': 'python3-numba',
    # numba's code generator: a dependency of numba's own (Debian's python3-numba depends on
    # python3-llvmlite), used directly by the kernel that calls DAQP's C functions
    'llvmlite': 'python3-numba',
    'pybullet': 'python3-pybullet-pip',
    'pybullet_data': 'python3-pybullet-pip',
    'pybullet_utils': 'python3-pybullet-pip',
    'rosbags': 'python3-rosbags-pip',
    'rclpy': 'rclpy',
    'ament_index_python': 'ament_index_python',
    'daqp': 'pip',
    'osqp': 'pip',
    'ruckig': 'pip',
    # the web view only (issue 23): optional, not on the README's pip line; without it web_view
    # says so in one line naming its pip line (test_optional_dependencies.py)
    'viser': 'optional pip',
    # the MuJoCo world and mujoco_bridge only (issue 38): optional as viser; without it
    # mujoco_bridge says so in one line (test_mujoco_sim.py)
    'mujoco': 'optional pip',
    # a Menagerie robot by name only (urdf_path: menagerie:<name>): without it that name is
    # refused with the pip line (test_menagerie.py)
    'mujoco_menagerie': 'optional pip',
}


def _imported_top_modules() -> set[str]:
    mods = set()
    for path in glob.glob(os.path.join(ROOT, 'orca_ros', '**', '*.py'), recursive=True):
        with open(path) as fh:
            tree = ast.parse(fh.read())
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                mods.update(a.name.split('.')[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                mods.add(node.module.split('.')[0])
        # modules imported by name (optional_import('daqp', ...), import_module)
        with open(path) as fh:
            mods.update(re.findall(r"optional_import\(\s*'([a-z_]+)", fh.read()))
    mods.update(MODULE.values())
    return {m for m in mods if m not in sys.stdlib_module_names and m != 'orca_ros'}


def test_every_imported_module_has_a_rosdep_key_or_the_pip_line():
    pkg = parse_package(os.path.join(ROOT, 'package.xml'))
    keys = {d.name for d in pkg.exec_depends}
    route = ros_route()
    pip_names = {spec.split('==')[0] for spec in route['pip'][2:]}
    uncovered = []
    for mod in sorted(_imported_top_modules()):
        if mod.endswith(('_msgs', '_srvs', '_interfaces')):
            key = mod  # interface packages: their own key
        else:
            assert mod in KEY_OF_MODULE, f'the package imports {mod}: add its rosdep key or pip'
            key = KEY_OF_MODULE[mod]
        if key == 'optional pip':
            if mod not in PIP:
                uncovered.append(f'{mod} (optional, but no pinned pip line to name)')
        elif key == 'pip':
            if mod not in pip_names:
                uncovered.append(f'{mod} (no rosdep key, not on the pip line)')
        elif key not in keys:
            uncovered.append(f'{mod} (rosdep key {key} not in package.xml)')
    assert not uncovered, uncovered
    # and the pip line holds the keyless packages only, each at its pinned version
    keyless = {m for m, k in KEY_OF_MODULE.items() if k == 'pip'}
    assert pip_names == keyless
    for spec in route['pip'][2:]:
        assert spec == PIP[spec.split('==')[0]], f"{spec}: pinned as {PIP[spec.split('==')[0]]}"


def test_rosdep_line_installs_from_the_workspace_sources():
    argv = ['rosdep', 'install', '--from-paths', 'src', '--ignore-src', '-y']
    assert ros_route()['rosdep'] == argv


def test_the_pip_line_runs():
    """The README's pip line, as written (the pinned set is installed already: a no-op)."""
    argv = ros_route()['pip']
    assert argv[:2] == ['pip', 'install']
    out = subprocess.run(
        [sys.executable, '-m', 'pip', 'install', '--no-deps', *argv[2:]],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
