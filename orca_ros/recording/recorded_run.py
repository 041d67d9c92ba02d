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
A recorded run read back from its rosbag2 file with ``rosbags`` (no ROS installation needed).

Times are the bag's receive stamps (simulated time when the recorder ran with ``use_sim_time``), in
seconds from the first joint state. Joint arrays are in the order of the commanded joints (the
diagnostics name them; else the joint states' own order).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..utils.optional_import import optional_import


@dataclass
class RecordedRun:
    path: str
    joints: list = field(default_factory=list)
    urdf: str = ''
    t_state: np.ndarray = field(default_factory=lambda: np.zeros(0))
    q: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    v: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    t_command: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tau: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    t_target: np.ndarray = field(default_factory=lambda: np.zeros(0))
    target: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    t_error: np.ndarray = field(default_factory=lambda: np.zeros(0))
    error: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    t_cycle: np.ndarray = field(default_factory=lambda: np.zeros(0))
    solve_time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    diagnostics: list = field(default_factory=list)  # (t, level, message, values dict)
    counts: dict = field(default_factory=dict)  # topic -> messages in the bag
    msgtypes: dict = field(default_factory=dict)  # topic -> message type
    duration: float = 0.0  # span of the bag's stamps [s]

    def configuration(self) -> dict:
        """Return the controller's configuration as its last diagnostics state it."""
        return dict(self.diagnostics[-1][3]) if self.diagnostics else {}


def _level(raw) -> int:
    return int.from_bytes(raw, 'little') if isinstance(raw, (bytes, bytearray)) else int(raw)


def read_run(path: str) -> RecordedRun:
    """Read a bag written by ``bag_recorder`` (any rosbag2 storage ``rosbags`` reads)."""
    highlevel = optional_import('rosbags.highlevel', 'reading a recorded run')
    run = RecordedRun(path=str(path))
    states, commands, targets, errors, cycles = [], [], [], [], []
    with highlevel.AnyReader([Path(path)]) as reader:
        run.duration = (reader.end_time - reader.start_time) * 1e-9
        for conn in reader.connections:
            run.counts[conn.topic] = run.counts.get(conn.topic, 0) + conn.msgcount
            run.msgtypes[conn.topic] = conn.msgtype
        for conn, stamp, raw in reader.messages():
            t = stamp * 1e-9
            msg = reader.deserialize(raw, conn.msgtype)
            topic = conn.topic
            if topic.endswith('robot_description'):
                run.urdf = msg.data
            elif conn.msgtype == 'sensor_msgs/msg/JointState':
                states.append((t, list(msg.name), msg.position, msg.velocity))
            elif topic.endswith('/commands'):
                commands.append((t, np.asarray(msg.data, dtype=float)))
            elif topic.endswith('/target_pose'):
                p = msg.pose.position
                targets.append((t, (p.x, p.y, p.z)))
            elif topic.endswith('/error'):
                errors.append((t, np.asarray(msg.data, dtype=float)))
            elif topic.endswith('/cycle_timing'):
                k = msg.layout.dim[1].size if len(msg.layout.dim) > 1 else len(msg.data) // 2
                cycles.append(np.asarray(msg.data, dtype=float).reshape(2, k))
            elif conn.msgtype == 'diagnostic_msgs/msg/DiagnosticArray':
                for st in msg.status:
                    run.diagnostics.append(
                        (t, _level(st.level), st.message, {kv.key: kv.value for kv in st.values})
                    )
    joints = run.configuration().get('joints', '')
    run.joints = joints.split(',') if joints else (states[0][1] if states else [])
    _states_into(run, states)
    t0 = run.t_state[0] if run.t_state.size else 0.0
    run.t_state = run.t_state - t0
    if commands:
        run.t_command = np.array([c[0] for c in commands]) - t0
        run.tau = np.vstack([c[1] for c in commands])
    if targets:
        run.t_target = np.array([x[0] for x in targets]) - t0
        run.target = np.array([x[1] for x in targets])
    if errors:
        run.t_error = np.array([e[0] for e in errors]) - t0
        run.error = np.vstack([e[1] for e in errors])
    if cycles:
        both = np.hstack(cycles)
        run.t_cycle, run.solve_time = both[0] - both[0, 0], both[1]
    run.diagnostics = [(t - t0, lv, m, vals) for t, lv, m, vals in run.diagnostics]
    return run


def _states_into(run: RecordedRun, states) -> None:
    if not states:
        return
    names = run.joints
    rows_q, rows_v, ts = [], [], []
    index_key, index = None, None
    for t, msg_names, pos, vel in states:
        if msg_names != index_key:
            where = {n: i for i, n in enumerate(msg_names)}
            if any(n not in where for n in names):
                continue  # a state of some other publisher
            index_key, index = msg_names, np.array([where[n] for n in names])
        ts.append(t)
        rows_q.append(np.asarray(pos, dtype=float)[index])
        rows_v.append(np.asarray(vel, dtype=float)[index])
    run.t_state = np.array(ts)
    run.q, run.v = np.vstack(rows_q), np.vstack(rows_v)
