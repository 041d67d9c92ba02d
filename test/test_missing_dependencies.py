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
The rosdep route: Python packages without a rosdep key (daqp, ruckig, osqp) missing.

The documented behaviour (README, "ROS 2 route"):
* daqp (the default solver) missing: the controller runs ProxQP (rosdep key ``proxsuite``) and
  says so in one WARN line with daqp's pip line;
* ruckig missing: the node refuses to start with one line naming ruckig's pip line (targets as
  steps would ask ~100 m/s^2 of the arm on the first cycle), exit code 1, no traceback;
* a solver asked for by name (osqp) missing: refused the same way;
* numba missing: the controller runs its reference path (plain Python, slower) and says so once.

"Missing" is made for the child process only: a ``sitecustomize`` on its PYTHONPATH sets the
modules to None in ``sys.modules``, which Python's import system treats as not installed.
"""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest


def hiding_env(tmp_path, *modules: str) -> dict:
    """Environment variables under which ``modules`` cannot be imported."""
    d = tmp_path / 'hide'
    d.mkdir(exist_ok=True)
    (d / 'sitecustomize.py').write_text(
        'import sys\n' + ''.join(f"sys.modules['{m}'] = None\n" for m in modules)
    )
    path = os.environ.get('PYTHONPATH', '')
    return {'PYTHONPATH': f'{d}{os.pathsep}{path}' if path else str(d)}


def run_python(code: str, env: dict, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, '-c', textwrap.dedent(code)],
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_core_without_daqp_falls_back_to_proxqp_and_controls(tmp_path):
    out = run_python(
        """
        import numpy as np
        import orca_ros as orca
        from orca_ros.examples.simple_controller import run
        res = run(orca.default_urdf_path(), 'daqp', duration=0.2)
        tau = res['torque']
        print('SOLVER', res['solver'], res['solved'] == res['cycles'], np.isfinite(tau).all(),
              float(np.abs(tau).max()))
        """,
        hiding_env(tmp_path, 'daqp'),
    )
    assert out.returncode == 0, out.stderr
    solver, ok, finite, peak = out.stdout.split('SOLVER ')[1].split()
    assert (solver, ok, finite) == ('proxqp', 'True', 'True'), out.stdout
    assert float(peak) > 1.0  # torques that hold the arm against gravity, not a zero command
    warnings = [ln for ln in out.stderr.splitlines() if 'WARNING' in ln]
    assert len(warnings) == 1, out.stderr
    assert 'pip install daqp==0.11.0' in warnings[0] and "using 'proxqp'" in warnings[0]
    assert 'Traceback' not in out.stderr


def test_core_without_numba_runs_the_reference_path_and_says_so_once(tmp_path):
    out = run_python(
        """
        import numpy as np
        import orca_ros as orca
        from orca_ros.examples.simple_controller import run
        res = run(orca.default_urdf_path(), 'daqp', duration=0.2)
        res2 = run(orca.default_urdf_path(), 'daqp', duration=0.2)
        print('RESULT', res['solved'] == res['cycles'], np.isfinite(res['torque']).all())
        """,
        hiding_env(tmp_path, 'numba'),
    )
    assert out.returncode == 0, out.stderr
    assert 'RESULT True True' in out.stdout, out.stdout
    warnings = [ln for ln in out.stderr.splitlines() if 'WARNING' in ln]
    assert len(warnings) == 1, out.stderr  # two controllers, one line
    assert 'pip install numba==0.68.1' in warnings[0] and 'reference path' in warnings[0]
    assert 'Traceback' not in out.stderr


def test_core_without_the_named_solver_refuses_with_its_pip_line(tmp_path):
    out = run_python(
        """
        import orca_ros as orca
        from orca_ros.utils.optional_import import MissingDependency
        robot = orca.RobotModel()
        robot.load_model_from_file(orca.default_urdf_path())
        try:
            orca.Controller('c', robot, solver='osqp')
        except MissingDependency as exc:
            print('REFUSED', exc)
        """,
        hiding_env(tmp_path, 'osqp'),
    )
    assert out.returncode == 0, out.stderr
    assert "REFUSED solver 'osqp' needs the Python package 'osqp': pip install osqp==1.1.3" in (
        out.stdout
    )


@pytest.fixture
def ros():
    pytest.importorskip('rclpy', reason='the nodes need rclpy')
    from orca_ros.ros.testing.launch_free import free_domain_id, Procs
    from orca_ros.ros.testing.probe import Probe

    return free_domain_id, Procs, Probe


def test_node_without_daqp_controls_with_proxqp_and_says_so_once(tmp_path, ros):
    free_domain_id, Procs, Probe = ros
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm_bridge('lockstep')
    procs.start_arm_controller('lockstep', env=hiding_env(tmp_path, 'daqp'))
    probe = Probe(domain)
    try:
        probe.wait_for(lambda: probe.sim_time() > 0.5, 60, 'the controller driving the bridge')
        target = probe.send_ee_offset([0.05, -0.05, 0.03])
        probe.wait_sim(3.0)
        err = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
        assert err < 1e-3, f'{err * 1e3:.2f} mm from the target with the fallback solver'
        log = procs.log('controller')
        warns = [ln for ln in log.splitlines() if 'WARN' in ln and 'daqp' in ln]
        assert len(warns) == 1, log[-3000:]
        assert 'pip install daqp==0.11.0' in warns[0] and "using 'proxqp'" in warns[0]
        assert 'solver proxqp' in log
        assert 'Traceback' not in log
    finally:
        probe.close()
        procs.stop()


def test_node_without_ruckig_refuses_with_the_pip_line(tmp_path, ros):
    free_domain_id, Procs, _ = ros
    procs = Procs(free_domain_id(), str(tmp_path))
    p = procs.start_arm_controller('lockstep', env=hiding_env(tmp_path, 'ruckig'))
    try:
        code = p.wait(timeout=120)
    finally:
        procs.stop()
    log = procs.log('controller')
    assert code == 1, log
    lines = [ln for ln in log.splitlines() if 'cannot run' in ln]
    assert len(lines) == 1, log
    assert 'pip install ruckig==0.19.4' in lines[0]
    assert 'trajectory.enabled: false' in lines[0]
    assert 'Traceback' not in log
