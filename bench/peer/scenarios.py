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
Scenario definitions shared by the orca_ros and TSID runners of bench/bench_tsid.py.

Pure numpy + pinocchio: this module is imported by both the project's venv and the benchmark's side
venv (Python 3.13, where TSID's wheel lives). A scenario fixes the robot (URDF file), its start
state, the tasks (frames, gains, weights), the contacts, the limits and the moving reference, so
that both controllers solve the same problem every step. The loop is closed by the same kinematic
integration on both sides (v += dt * dv, q = integrate(q, dt * v)); the tasks' references move and
carry no feed-forward, so the final task errors are lags that both controllers must reproduce.
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import sys

import numpy as np

DT = 0.001
_HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(_HERE))


def example_robot_data(rel: str) -> str:
    """
    Path of a file of the (pinned) example-robot-data wheel.

    Found in any site-packages on sys.path.
    """
    for p in sys.path:
        cand = os.path.join(p, 'cmeel.prefix', 'share', 'example-robot-data', 'robots', rel)
        if os.path.exists(cand):
            return cand
    hits = glob.glob(
        os.path.join(
            sys.prefix,
            'lib',
            'python*',
            'site-packages',
            'cmeel.prefix',
            'share',
            'example-robot-data',
            'robots',
            rel,
        )
    )
    if hits:
        return hits[0]
    raise FileNotFoundError(
        f"example-robot-data file '{rel}' not found (pip install example-robot-data)"
    )


OMEGA = 2.0 * np.pi * 0.5  # 0.5 Hz references


def _talos_half_sitting(model):
    """
    Talos's half-sitting joint angles from its SRDF.

    In the model's joint order (root excluded).
    """
    import pinocchio as pin

    pin.loadReferenceConfigurations(model, example_robot_data('talos_data/srdf/talos.srdf'), False)
    q = np.array(model.referenceConfigurations['half_sitting'])
    return q[7:]


SCENARIOS = {
    # Panda 9 DoF (7 + 2 fingers), fixed base: end-effector 6-D task following a moving point,
    # posture, torque / position / velocity limits from the URDF.
    'panda': {
        'urdf': ('erd', 'panda_description/urdf/panda.urdf'),
        'floating': False,
        'q0': [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785, 0.02, 0.02],
        'ee': {
            'frame': 'panda_hand',
            'kp': 100.0,
            'kd': 20.0,
            'weight': 1.0,
            'amplitude': [0.0, 0.10, 0.05],
        },
        'posture': {'kp': 10.0, 'kd': 6.32, 'weight': 1e-3},
        'limits': ('torque', 'position', 'velocity'),
        'duration': 2.0,
    },
    # The project's 12-DoF quadruped, floating base, four point contacts (4-face pyramids), trunk
    # 6-D task swaying sideways, posture, torque limits.
    'quadruped': {
        'urdf': ('repo', 'urdf/quadruped.urdf'),
        'floating': True,
        'base_height': 0.2 * 2 * np.cos(0.7) + 0.02,
        'q0': list(np.tile([0.0, 0.7, -1.4], 4)),
        'ee': {
            'frame': 'trunk',
            'kp': [900.0] * 3 + [400.0] * 3,
            'kd': [60.0] * 3 + [40.0] * 3,
            'weight': 1.0,
            'amplitude': [0.0, 0.03, 0.0],
        },
        'posture': {'kp': 25.0, 'kd': 10.0, 'weight': 1e-3},
        'points': {
            'frames': ['FL_foot', 'FR_foot', 'HL_foot', 'HR_foot'],
            'mu': 0.7,
            'fmin': 0.0,
            'fmax': 300.0,
        },
        'limits': ('torque',),
        'duration': 2.0,
    },
    # Talos 38 DoF (example-robot-data talos_reduced), floating base, both soles as rectangular
    # surface contacts (4 corners, 4-face pyramids), CoM swaying +-5 cm sideways, posture.
    'talos': {
        'urdf': ('erd', 'talos_data/robots/talos_reduced.urdf'),
        'floating': True,
        'q0': 'talos_half_sitting',
        'com': {'kp': 30.0, 'kd': 10.95, 'weight': 1.0, 'amplitude': [0.0, 0.05, 0.0]},
        'posture': {'kp': 10.0, 'kd': 6.32, 'weight': 1e-3},
        'soles': {
            'frames': ['leg_left_sole_fix_joint', 'leg_right_sole_fix_joint'],
            'half_length': 0.1,
            'half_width': 0.065,
            'mu': 0.3,
            'fmin': 0.0,
            'fmax': 1500.0,
        },
        'limits': (),
        'duration': 2.0,
    },
}


def urdf_path(sc) -> str:
    kind, rel = sc['urdf']
    return example_robot_data(rel) if kind == 'erd' else os.path.join(REPO, rel)


def sole_corners(sc) -> np.ndarray:
    """(4, 3) corners of a sole in its frame."""
    s = sc['soles']
    a, b = s['half_length'], s['half_width']
    return np.array([[a, b, 0.0], [a, -b, 0.0], [-a, -b, 0.0], [-a, b, 0.0]])


def initial_configuration(sc, model):
    """
    Pinocchio configuration (q) of the start state.

    A floating base stands on the ground (z of the lowest contact frame at 0, or the given base
    height).
    """
    import pinocchio as pin

    qj = (
        _talos_half_sitting(model)
        if sc['q0'] == 'talos_half_sitting'
        else np.asarray(sc['q0'], float)
    )
    if not sc['floating']:
        return qj.copy()
    q = np.concatenate(([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], qj))
    if 'base_height' in sc:
        q[2] = sc['base_height']
        return q
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    frames = sc['soles']['frames']
    q[2] = -min(data.oMf[model.getFrameId(f)].translation[2] for f in frames)
    return q


def reference_offset(amplitude, t: float) -> np.ndarray:
    """
    Offset of a moving reference from its start.

    A * (sin(wt), sin(wt), 1 - cos(wt)) per axis pattern (y follows sin, z follows 1 - cos, x
    follows sin).
    """
    a = np.asarray(amplitude, float)
    s, c = np.sin(OMEGA * t), 1.0 - np.cos(OMEGA * t)
    return np.array([a[0] * s, a[1] * s, a[2] * c])


def steps(sc) -> int:
    return int(round(sc['duration'] / DT))


def stats(times_s) -> dict:
    t = np.asarray(times_s) * 1e6
    return {
        'median_us': float(np.median(t)),
        'p99_us': float(np.percentile(t, 99)),
        'n': int(t.size),
    }


def cli(run) -> None:
    """Run a peer's command line ``SCENARIO [--steps N]``: print its run as JSON."""
    ap = argparse.ArgumentParser()
    ap.add_argument('scenario', choices=sorted(SCENARIOS))
    ap.add_argument('--steps', type=int, default=None)
    a = ap.parse_args()
    print(json.dumps(run(a.scenario, a.steps)))
