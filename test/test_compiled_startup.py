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
The compiled cycle from a read-only install, and its disk cache.

A copy of the package on a read-only mount (as a ROS install under /opt may be; a private mount
namespace, so that even root cannot write there) runs a controller twice in fresh processes with
an empty user cache folder: the kernels compile into that folder the first time and load from it
the second; construction is faster the second time.
"""

import os
import shutil
import subprocess
import sys
import textwrap
import types

import orca_ros
import pytest

RUN = textwrap.dedent(
    """
    import time
    import numpy as np
    import orca_ros as orca
    assert orca.__file__.startswith({root!r}), orca.__file__
    t0 = time.perf_counter()
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]), np.zeros(7))
    c = orca.Controller('c', robot)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('link_7')
    c.add_task(orca.JointAccelerationTask, 'posture')
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position')
    c.activate_tasks_and_constraints()
    c.get_levels()  # configuration: the kernels compile or load here
    built = time.perf_counter() - t0
    ok = all(c.update(k * 1e-3, 1e-3) for k in range(10))
    tau = c.get_joint_torque_command()
    print('RESULT', ok, c.compiled_cycle is not None, bool(np.isfinite(tau).all()), built)
    """
)


def _read_only_command(site, _code):
    """Run ``python -c code`` with ``site`` mounted read-only in a private mount namespace."""
    script = (
        f'mount --bind {site} {site} && mount -o remount,ro,bind {site} {site} && '
        f'exec {sys.executable} -c "$ORCA_CODE"'
    )
    return ['unshare', '-m', 'sh', '-c', script]


def test_read_only_install_caches_its_kernels_in_the_user_folder(tmp_path):
    site = tmp_path / 'site'
    shutil.copytree(
        os.path.dirname(orca_ros.__file__),
        site / 'orca_ros',
        ignore=shutil.ignore_patterns('__pycache__'),
    )
    root = os.path.dirname(os.path.dirname(orca_ros.__file__))
    shutil.copytree(os.path.join(root, 'urdf'), site / 'urdf')  # the shipped files, as installed
    cache = tmp_path / 'cache'
    env = dict(os.environ, PYTHONPATH=str(site), XDG_CACHE_HOME=str(cache), HOME=str(tmp_path))
    env.pop('NUMBA_CACHE_DIR', None)
    env['ORCA_CODE'] = RUN.format(root=str(site))
    runs = []
    for _ in range(2):
        out = subprocess.run(
            _read_only_command(site, None), env=env, capture_output=True, text=True, timeout=600,
            cwd=str(tmp_path),
        )
        assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
        line = [ln for ln in out.stdout.splitlines() if ln.startswith('RESULT')][0]
        ok, compiled, finite, built = line.split()[1:]
        assert (ok, compiled, finite) == ('True', 'True', 'True'), line
        runs.append(float(built))
    cached = [f for _, _, fs in os.walk(cache) for f in fs if f.endswith('.nbi')]
    in_package = [f for _, _, fs in os.walk(site) for f in fs if f.endswith(('.nbi', '.nbc'))]
    assert cached, 'no kernel cached in the user folder'
    assert not in_package, f'kernels cached inside the read-only package: {in_package}'
    print(f'construction: cold {runs[0]:.2f} s, warm {runs[1]:.2f} s')
    # loading cached kernels, not compiling them: measured cold 44 s (a loaded machine), warm
    # 0.3-0.6 s; bench/bench_startup.py measures it on each scenario
    assert runs[1] < 0.2 * runs[0]


def test_an_index_naming_a_module_that_is_gone_is_a_stale_one(tmp_path, monkeypatch):
    """
    A cache written by another version of the package: its index names a module gone since.

    numba unpickles an index before it compares its stamp, and unpickling one that names a
    module no longer there raises (a kernel moved to another file between versions: every
    process of the new version failed at its first compile). Read through orca_ros.utils.jit,
    such an index is empty: the kernel compiles anew and the index is written again.
    """
    pytest.importorskip('numba')
    from numba.core import caching
    from orca_ros.utils import jit  # noqa: F401 (its patch of numba's cache)

    gone = types.ModuleType('orca_ros_module_gone_since')
    exec('class Record:\n    pass', gone.__dict__)
    gone.Record.__module__ = gone.__name__
    monkeypatch.setitem(sys.modules, gone.__name__, gone)
    index = caching.IndexDataCacheFile(cache_path=str(tmp_path), filename_base='kernel',
                                       source_stamp='this version')
    index._save_index({('signature',): gone.Record()})
    monkeypatch.delitem(sys.modules, gone.__name__)
    load = caching.IndexDataCacheFile._load_index
    with pytest.raises(ImportError):
        load.original(index)  # numba's own reading
    assert load(index) == {}
