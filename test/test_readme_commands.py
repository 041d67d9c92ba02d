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
The README's commands, as written: the two commands, the core example, the nodes in five commands.

The two commands must be the entry points ``scripts/`` has (and ``.ci/run`` calls the test one).
The Python block runs and its assertion holds. Of the five node commands, the two that start the
nodes run as written (console scripts of this venv, from the repository); ros2cli is not on
PyPI, so the three ``ros2`` lines are carried out here by what they name: their topic or service,
its type and the fields given in YAML, through rclpy; their effects are checked (the hand at the
target, the task switched off, diagnostics read).
"""

import importlib
import os
import shlex
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest
from readme_blocks import code_block_after, ROOT
import yaml


def test_readme_is_short():
    with open(os.path.join(ROOT, 'README.md')) as fh:
        text = fh.read()
    assert len(text.splitlines()) <= 200
    assert '![' in text.split('## The two commands')[0]  # a picture before the commands
    assert os.path.isfile(os.path.join(ROOT, 'docs', 'images', 'main_job_run.png'))


def test_the_two_commands_are_the_scripts_entry_points():
    block = code_block_after('## The two commands')
    lines = [ln.split('#')[0].strip() for ln in block.splitlines()]
    commands = [ln for ln in lines if ln]
    assert commands == ['bash scripts/run_demo.sh', 'bash scripts/run_tests.sh']
    # the scripts of scripts/ that call themselves a README command are exactly these two
    entry = sorted(
        f'bash scripts/{f}' for f in os.listdir(os.path.join(ROOT, 'scripts'))
        if f.endswith('.sh') and 'README command' in open(os.path.join(ROOT, 'scripts', f)).read()
    )
    assert entry == sorted(commands)
    with open(os.path.join(ROOT, '.ci', 'run')) as fh:
        assert 'bash scripts/run_tests.sh' in fh.read()
    for cmd in commands:
        run = subprocess.run(['bash', '-n', os.path.join(ROOT, cmd.split()[1])])
        assert run.returncode == 0, cmd
    # what they run: the main job (which test_ros_main_job.py runs end to end) and pytest on test/
    with open(os.path.join(ROOT, 'scripts', 'run_demo.sh')) as fh:
        assert 'python -m orca_ros.ros.main_job "$@"' in fh.read()
    with open(os.path.join(ROOT, 'scripts', 'run_tests.sh')) as fh:
        assert 'python -m pytest -q --durations=40 test "$@"' in fh.read()
    with open(os.path.join(ROOT, 'test', 'test_ros_main_job.py')) as fh:
        assert "'-m', 'orca_ros.ros.main_job'" in fh.read()


def test_the_core_example_runs(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    exec(compile(code_block_after('## The core in Python'), 'README.md', 'exec'), {})


def test_the_collision_picture_command_shows_what_the_readme_says(tmp_path):
    """`python -m orca_ros.examples.round_the_ball`: 20 mm kept round the ball; through without."""
    from orca_ros.examples import round_the_ball

    with open(os.path.join(ROOT, 'README.md')) as fh:
        text = fh.read()
    assert '`python -m orca_ros.examples.round_the_ball`' in text
    assert 'it keeps 20 mm between its rounded hulls' in text
    assert os.path.exists(os.path.join(ROOT, 'docs', 'images', 'round_the_ball.png'))
    runs = {flag: round_the_ball.run(flag) for flag in (False, True)}
    with_, without = runs[True], runs[False]
    assert abs(with_['distance'].min() - 0.02) < 1e-3 and with_['failures'] == 0
    assert np.linalg.norm(with_['hand'][-1] - with_['reference'][-1]) < 1e-3
    assert without['distance'].min() < -0.05  # through the ball
    round_the_ball.draw(runs, str(tmp_path / 'picture.png'), 0.02)
    assert (tmp_path / 'picture.png').stat().st_size > 10_000


def _message(type_name: str, fields: dict):
    """Make a ROS message or service request of ``pkg/msg/Name`` from a dict, as ros2cli does."""
    pkg, kind, name = type_name.split('/')
    cls = getattr(importlib.import_module(f'{pkg}.{kind}'), name)
    if kind == 'srv':
        cls = cls.Request

    def fill(msg, values):
        for key, value in values.items():
            if isinstance(value, dict):
                fill(getattr(msg, key), value)
            else:
                setattr(msg, key, type(getattr(msg, key))(value))
        return msg

    return fill(cls(), fields or {})


def _node_lines():
    return [
        ln.rstrip(' &') for ln in code_block_after('## The nodes in five commands').splitlines()
        if ln.strip()
    ]


def test_the_five_node_commands(tmp_path):
    pytest.importorskip('rclpy')
    from orca_ros.ros.testing.launch_free import _die_with_parent, free_domain_id, ros_env
    from orca_ros.ros.testing.probe import Probe

    lines = _node_lines()
    assert [shlex.split(ln)[0] for ln in lines] == [
        'pybullet_bridge', 'orca_controller', 'ros2', 'ros2', 'ros2'
    ]
    domain, procs = free_domain_id(), []
    bindir = os.path.dirname(sys.executable)
    probe = None
    try:
        for k, line in enumerate(lines[:2]):
            argv = shlex.split(line)
            log = open(tmp_path / f'node{k}.log', 'w')
            procs.append((subprocess.Popen(
                [os.path.join(bindir, argv[0]), *argv[1:]], cwd=ROOT, env=ros_env(domain),
                stdout=log, stderr=subprocess.STDOUT, preexec_fn=_die_with_parent,
            ), log))
        probe = Probe(domain)
        probe.wait_for(lambda: len(probe.commands) > 100, 120, 'the controller commanding the arm')

        # ros2 topic pub --once <topic> <type> <fields>: published until it takes effect
        # (discovery may drop a new publisher's first message), then the hand must get there
        pub = shlex.split(lines[2])
        assert pub[1:4] == ['topic', 'pub', '--once']
        topic, type_name, fields = pub[4], pub[5], yaml.safe_load(pub[6])
        msg = _message(type_name, fields)
        publisher = probe.node.create_publisher(type(msg), topic, 10)
        p = fields['pose']['position']
        goal = np.array([p['x'], p['y'], p['z']])
        # the text's "5 cm above the pose it is started in" (the bridge line's initial_positions)
        q0 = yaml.safe_load(shlex.split(lines[0])[3].split(':=', 1)[1])
        started = probe.ee_pose(np.array(q0, dtype=float))
        assert np.allclose(goal - started[:3, 3], [0.0, 0.0, 0.05], atol=2e-4)
        o = fields['pose']['orientation']
        quat = np.array([o.get('x', 0.0), o.get('y', 0.0), o.get('z', 0.0), o['w']])
        # x y z w, the start's orientation (SE3ToXYZQUAT: pin.Quaternion(R) leaks in Pinocchio 4.1)
        same = pin.SE3ToXYZQUAT(pin.SE3(started[:3, :3], started[:3, 3]))[3:]
        assert abs(abs(quat @ same) - 1.0) < 1e-4
        now = probe.ee_pose()[2, 3]
        probe.publish_until(
            lambda: publisher.publish(msg),
            lambda: probe.ee_pose()[2, 3] > now + 0.01,
            'the hand moving up',
        )
        probe.wait_for(
            lambda: np.linalg.norm(probe.ee_pose()[:3, 3] - goal) < 1e-3, 60,
            'the hand within 1 mm of the target',
        )

        # ros2 service call <service> <type> <fields>
        call = shlex.split(lines[3])
        assert call[1:3] == ['service', 'call']
        request = _message(call[4], yaml.safe_load(call[5]))
        answer = probe.call(_srv_type(call[4]), call[3], request)
        assert answer.success, answer.message

        # ros2 topic echo --once /diagnostics: the controller's report, the task switched off
        echo = shlex.split(lines[4])
        assert echo[1:] == ['topic', 'echo', '--once', '/diagnostics']
        probe.wait_for(
            lambda: 'ee' not in probe.diagnostics.get('active_tasks', 'ee').split(','), 60,
            'diagnostics without the ee task among the active ones',
        )
        assert probe.diagnostics['qp_failures'] == '0'
        assert 'posture' in probe.diagnostics['active_tasks'].split(',')
    finally:
        if probe is not None:
            probe.close()
        for p, log in procs:
            p.terminate()
        for p, log in procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
            log.close()


def _srv_type(type_name: str):
    pkg, kind, name = type_name.split('/')
    return getattr(importlib.import_module(f'{pkg}.{kind}'), name)
