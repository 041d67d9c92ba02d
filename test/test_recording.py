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
Recorded runs read back without ROS.

A rosbag2 (MCAP) file is written here with rosbags' own serializer, as bag_recorder writes it,
then read, summarised and plotted.

The run is made up so the answers are known: joint_2's torque command sits at its effort limit
from 1.0 s to 1.5 s, joint_5 reaches its upper position limit at 1.8 s, the task error decays.
"""

import numpy as np
import orca_ros as orca
from orca_ros.recording import read_run
from orca_ros.recording.plot_command import main as plot_main
from orca_ros.recording.run_report import joint_limits, report
import pytest

rosbags = pytest.importorskip('rosbags')
JOINTS = [f'joint_{i}' for i in range(7)]


def _write_bag(path, urdf):
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import get_typestore, Stores

    ts = get_typestore(Stores.ROS2_JAZZY)
    JointState = ts.types['sensor_msgs/msg/JointState']
    Header = ts.types['std_msgs/msg/Header']
    Time = ts.types['builtin_interfaces/msg/Time']
    F64 = ts.types['std_msgs/msg/Float64MultiArray']
    Layout = ts.types['std_msgs/msg/MultiArrayLayout']
    Dim = ts.types['std_msgs/msg/MultiArrayDimension']
    String = ts.types['std_msgs/msg/String']
    Diag = ts.types['diagnostic_msgs/msg/DiagnosticArray']
    Status = ts.types['diagnostic_msgs/msg/DiagnosticStatus']
    KV = ts.types['diagnostic_msgs/msg/KeyValue']
    robot = orca.RobotModel()
    robot.load_model_from_string(urdf)
    lo, hi = robot.get_joint_position_limits()
    tau_max = robot.get_joint_torque_limits()
    t0 = 100.0  # stamps start anywhere: times are read relative to the first joint state
    with Writer(path, version=8, storage_plugin=StoragePlugin.MCAP) as w:
        c = {
            'desc': w.add_connection('/robot_description', 'std_msgs/msg/String', typestore=ts),
            'js': w.add_connection('/joint_states', 'sensor_msgs/msg/JointState', typestore=ts),
            'cmd': w.add_connection(
                '/effort_controller/commands', 'std_msgs/msg/Float64MultiArray', typestore=ts
            ),
            'err': w.add_connection(
                '/orca_controller/tasks/ee/error', 'std_msgs/msg/Float64MultiArray', typestore=ts
            ),
            'cyc': w.add_connection(
                '/orca_controller/cycle_timing', 'std_msgs/msg/Float64MultiArray', typestore=ts
            ),
            'diag': w.add_connection(
                '/diagnostics', 'diagnostic_msgs/msg/DiagnosticArray', typestore=ts
            ),
        }

        def put(key, t, msg, kind):
            w.write(c[key], int(round((t0 + t) * 1e9)), ts.serialize_cdr(msg, kind))

        put('desc', -0.5, String(data=urdf), 'std_msgs/msg/String')
        empty = Layout(dim=[], data_offset=0)
        for k in range(2001):  # 2 s at 1 kHz, joint states and commands
            t = k * 1e-3
            q = 0.5 * (lo + hi)
            q[5] = hi[5] if t >= 1.8 else q[5]
            stamp = Time(sec=int(t0 + t), nanosec=int(round(((t0 + t) % 1) * 1e9)))
            put('js', t, JointState(header=Header(stamp=stamp, frame_id=''), name=JOINTS,
                                    position=q, velocity=np.zeros(7), effort=np.zeros(7)),
                'sensor_msgs/msg/JointState')
            tau = np.zeros(7)
            tau[2] = tau_max[2] if 1.0 <= t < 1.5 else 10.0
            put('cmd', t, F64(layout=empty, data=tau), 'std_msgs/msg/Float64MultiArray')
            if k % 20 == 0:
                e = np.r_[0.1 * np.exp(-3 * t) * np.ones(3), np.zeros(3)]
                put('err', t, F64(layout=empty, data=e), 'std_msgs/msg/Float64MultiArray')
                n = 20 if k else 1
                stamps = t0 + t - 1e-3 * np.arange(n)[::-1]
                lay = Layout(dim=[Dim(label='field', size=2, stride=2 * n),
                                  Dim(label='cycle', size=n, stride=n)], data_offset=0)
                put('cyc', t, F64(layout=lay, data=np.r_[stamps, np.full(n, 2e-4)]),
                    'std_msgs/msg/Float64MultiArray')
            if k % 500 == 0:
                values = {'solver': 'daqp', 'resolution_strategy': 'one_level_weighted',
                          'update_rate_hz': '1000', 'trigger': 'joint_state',
                          'joints': ','.join(JOINTS)}
                st = Status(level=0, name='orca', message='controlling', hardware_id='lwr',
                            values=[KV(key=a, value=b) for a, b in values.items()])
                put('diag', t, Diag(header=Header(stamp=stamp, frame_id=''), status=[st]),
                    'diagnostic_msgs/msg/DiagnosticArray')
    return lo, hi, tau_max


def test_a_recorded_run_reads_back_and_reports_what_saturated(tmp_path, lwr_urdf):
    urdf = open(lwr_urdf).read()
    bag = tmp_path / 'run'
    lo, hi, tau_max = _write_bag(bag, urdf)
    run = read_run(str(bag))
    assert run.joints == JOINTS and run.urdf == urdf
    assert run.q.shape == (2001, 7) and run.tau.shape == (2001, 7)
    np.testing.assert_allclose(run.t_state[[0, -1]], [0.0, 2.0], atol=1e-9)
    assert run.counts['/joint_states'] == 2001
    assert run.solve_time.size == 2001 and np.all(np.diff(run.t_cycle) > 0)
    assert run.configuration()['solver'] == 'daqp'
    limits = joint_limits(run)
    np.testing.assert_allclose(limits.lower, lo)
    lines = report(run)
    sat = [ln for ln in lines if ln.startswith('SATURATED')]
    assert len(sat) == 2, lines
    text = f'joint_2 torque at its limit {tau_max[2]:.3g} for 25.0% of the run, first at 1.00 s'
    assert any(text in ln for ln in sat), sat
    assert any('joint_5 position' in ln and 'first at 1.80 s' in ln for ln in sat)
    assert 'solve time per cycle: median 200 us' in '\n'.join(lines)


def test_plot_command_draws_a_bag(tmp_path, lwr_urdf, capsys):
    bag = tmp_path / 'run'
    _write_bag(bag, open(lwr_urdf).read())
    assert plot_main([str(bag)]) == 0
    out = capsys.readouterr().out
    assert 'SATURATED: joint_2 torque' in out
    png = tmp_path / 'run.png'
    assert png.stat().st_size > 50_000
    assert plot_main([str(tmp_path / 'nothing')]) == 2
