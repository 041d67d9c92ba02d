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
The main job (the demo) end to end, and the rosbag2 file it records, read back with rosbags.

In its own module: the lockstep pair of test_ros_nodes' module fixture runs flat out until that
module ends, and would slow this run down on a 2-core machine.
"""

import os
import subprocess
import sys

import numpy as np


def test_main_job_reaches_every_target_and_records_the_run(tmp_path):
    from rosbags.highlevel import AnyReader
    from pathlib import Path

    bag = tmp_path / 'run'
    # the timeout is a failsafe (a busy machine may take minutes), not a speed claim
    proc = subprocess.run(
        [sys.executable, '-m', 'orca_ros.ros.main_job', '--output-dir', str(tmp_path),
         '--bag', str(bag), '--web'],
        capture_output=True,
        text=True,
        timeout=900,
        env=dict(os.environ, MPLBACKEND='Agg'),
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    out = proc.stdout
    assert 'RESULT: every target reached' in out
    assert out.count(' mm ') >= 5 and 'NOT REACHED' not in out
    assert '-0.000' not in out and 'e-4' not in out.split('solve time')[0]
    assert (tmp_path / 'main_job_run.png').stat().st_size > 50_000
    assert (tmp_path / 'main_job_path.png').stat().st_size > 10_000
    # --web: the page's URL printed; the view had the robot and the end effector's task
    assert 'web view: http://127.0.0.1:' in out
    web_log = (tmp_path / 'run.logs' / 'web_view.log').read_text()
    assert 'robot: 8 visuals' in web_log and "task 'ee'" in web_log, web_log
    # the nodes' output is kept next to the run's bag (it was left in /tmp)
    for node in ('bridge', 'controller', 'recorder'):
        assert (tmp_path / 'run.logs' / f'{node}.log').stat().st_size > 0

    expected = {
        '/joint_states': 'sensor_msgs/msg/JointState',
        '/effort_controller/commands': 'std_msgs/msg/Float64MultiArray',
        '/orca_controller/tasks/ee/target_pose': 'geometry_msgs/msg/PoseStamped',
        '/orca_controller/tasks/ee/error': 'std_msgs/msg/Float64MultiArray',
        '/orca_controller/cycle_timing': 'std_msgs/msg/Float64MultiArray',
        '/diagnostics': 'diagnostic_msgs/msg/DiagnosticArray',
        '/robot_description': 'std_msgs/msg/String',
    }
    assert list(bag.glob('*.mcap')), 'the bag must use the MCAP storage'
    lag, n_states, cmds, cycle_stamps, targets, counts = [], 0, [], [], set(), {}
    with AnyReader([Path(bag)]) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == expected
        counts = {c.topic: c.msgcount for c in reader.connections}
        span = (reader.end_time - reader.start_time) * 1e-9
        for conn, stamp, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.topic == '/joint_states':
                n_states += 1
                lag.append(stamp * 1e-9 - (msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9))
            elif conn.topic == '/effort_controller/commands':
                cmds.append(np.asarray(msg.data))
            elif conn.topic == '/orca_controller/cycle_timing':
                k = msg.layout.dim[1].size
                cycle_stamps.extend(np.asarray(msg.data)[:k])
            elif conn.topic.endswith('target_pose'):
                p = msg.pose.position
                targets.add((p.x, p.y, p.z))
    # one command per simulated millisecond (lockstep), every one recorded (reliable QoS)
    assert counts['/robot_description'] == 1
    assert len(cmds) > 3000 and {c.size for c in cmds} == {7}
    assert all(np.isfinite(c).all() and np.abs(c).max() < 200.0 for c in cmds)
    # joint states are best effort (sensor data): a few may be lost, not a large part
    assert n_states > 0.9 * len(cmds)
    # bag stamps are simulated time (use_sim_time): they match the states' own stamps (wall-clock
    # stamps would be ~1.7e9 s off). The median, not a high percentile: a busy recorder takes in
    # /clock late and lags by a backlog of simulated steps (once 0.11 s at p99)
    assert np.median(np.abs(lag)) < 0.01
    assert abs(span - len(cmds) * 1e-3) < 0.1 * span
    # the four targets of the job, every one in the bag (each repeated until the arm moved and the
    # recorder logged its receipt: beside two CPU burners the recorder once missed one)
    sent = {
        tuple(float(x) for x in line[28:56].split())
        for line in out.splitlines()
        if line.startswith('target ')
    }
    assert len(sent) == 4, out
    assert {tuple(float(f'{round(x, 3) + 0.0:+.3f}') for x in p) for p in targets} == sent
    assert len(targets) == 4
    receipts = (tmp_path / 'run.logs' / 'recorder.log').read_text().count(
        'recorded /orca_controller/tasks/ee/target_pose message '
    )
    assert receipts == 4
    c = np.array(cycle_stamps)
    assert np.all(np.diff(c) > 0) and abs(c.size - len(cmds)) < 0.02 * len(cmds)
    assert counts['/diagnostics'] >= 5 and counts['/orca_controller/tasks/ee/error'] > 100

    from orca_ros.recording.plot_command import main as plot_main

    png = tmp_path / 'replot.png'
    import contextlib
    import io

    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert plot_main([str(bag), '--output', str(png)]) == 0
    report = text.getvalue()
    assert 'solver daqp, multi_level_weighted, 1000 Hz (joint_state)' in report
    assert 'solve time per cycle: median' in report
    assert 'limits: no position, velocity or torque limit reached' in report
    assert png.stat().st_size > 50_000


def _children(pid: int) -> set[int]:
    """Return the live child processes of ``pid`` (Linux)."""
    kids = set()
    for task in os.listdir(f'/proc/{pid}/task'):
        with open(f'/proc/{pid}/task/{task}/children') as fh:
            kids |= {int(k) for k in fh.read().split()}
    return kids


def test_main_job_on_mujoco_reaches_every_target_then_stays_until_ctrl_c(tmp_path):
    """
    ``--sim mujoco --stay``: the same job on the other simulator, then the arm left running.

    Every target within the job's 1 mm on MuJoCo (acceptance 1 of the MuJoCo issue); after the
    report the bridge and the controller run on (the recorder stopped: its bag was read for the
    report) until SIGINT, which ends them all and the job with 0.
    """
    import signal
    import time

    bag = tmp_path / 'run'
    output = tmp_path / 'job.out'
    proc = subprocess.Popen(
        [sys.executable, '-m', 'orca_ros.ros.main_job', '--output-dir', str(tmp_path),
         '--bag', str(bag), '--sim', 'mujoco', '--stay'],
        stdout=output.open('w'), stderr=subprocess.STDOUT,
        env=dict(os.environ, MPLBACKEND='Agg', PYTHONUNBUFFERED='1'),
    )
    staying = 'Ctrl-C ends them'
    try:
        deadline = time.time() + 900  # a failsafe (a busy machine may take minutes), no claim
        while (time.time() < deadline and proc.poll() is None
               and staying not in output.read_text()):
            time.sleep(0.1)
        text = output.read_text()
        assert staying in text and proc.poll() is None, text[-3000:]
        assert '(mujoco_bridge + orca_controller, lockstep)' in text
        assert 'RESULT: every target reached' in text and 'NOT REACHED' not in text
        assert text.count(' mm ') >= 5
        logs = tmp_path / 'run.logs'
        assert 'mujoco bridge: 7 joints, mode lockstep' in (logs / 'bridge.log').read_text()
        # staying: the bridge and the controller alive and stepping, the recorder stopped
        names = {}
        for kid in _children(proc.pid):
            with open(f'/proc/{kid}/cmdline') as fh:
                names[kid] = fh.read()
        assert sum('mujoco_bridge' in c for c in names.values()) == 1, names
        assert sum('controller_node' in c for c in names.values()) == 1, names
        assert not any('bag_recorder' in c for c in names.values()), names
        cpu0 = {k: _cpu_ticks(k) for k in names}
        deadline = time.time() + 60
        while time.time() < deadline and not all(_cpu_ticks(k) > cpu0[k] for k in names):
            time.sleep(0.1)  # until each of them has run (a busy machine may hold one back)
        assert all(_cpu_ticks(k) > cpu0[k] for k in names), 'the nodes stopped working'
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=60)
        assert proc.returncode == 0, output.read_text()[-3000:]
        assert 'stopping the nodes' in output.read_text()
        assert not any(os.path.exists(f'/proc/{k}') and _state(k) != 'Z' for k in names), names
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def _cpu_ticks(pid: int) -> int:
    with open(f'/proc/{pid}/stat') as fh:
        fields = fh.read().rsplit(')', 1)[1].split()
    return int(fields[11]) + int(fields[12])  # utime + stime


def _state(pid: int) -> str:
    try:
        with open(f'/proc/{pid}/stat') as fh:
            return fh.read().rsplit(')', 1)[1].split()[0]
    except FileNotFoundError:
        return 'gone'
