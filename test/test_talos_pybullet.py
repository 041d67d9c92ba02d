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
Talos (example-robot-data, 38 DoF, ~90 kg) sways its CoM in PyBullet (issue 11, item 1).

The same controller as ``test_talos_balance.py`` (default settings, two SurfaceContact soles,
CoM +-5 cm at 0.5 Hz, posture), closed on PyBullet instead of a kinematic integration. The URDF's
``package://`` meshes are resolved for PyBullet, and each sole's collision shape is a box of the
contact model's size: on the convex hulls of the ankle meshes PyBullet's contacts throw the robot
off the ground within 2 s (measured: base 17 m high at t = 2 s), on boxes it stands.
"""

import os

import numpy as np
from orca_ros.sim import replace_collisions_with_boxes, resolve_package_uris, SimServer
import pytest
from test_talos_balance import _talos, AMPLITUDE, CORNERS, DT, OMEGA

SOLE_LINKS = {'leg_left_6_link': 'left_sole_link', 'leg_right_6_link': 'right_sole_link'}
SOLE_BELOW_ANKLE = 0.107  # leg_*_sole_fix_joint: the sole frame 0.107 m under the ankle link
THICKNESS = 0.02


def _talos_urdf_for_pybullet(example_robot_urdf, path):
    src = example_robot_urdf('talos_data/robots/talos_reduced.urdf')
    with open(src) as f:
        text = resolve_package_uris(f.read(), src)
    size = (2 * CORNERS[:, 0].max(), 2 * CORNERS[:, 1].max(), THICKNESS)
    centre = (0.0, 0.0, -SOLE_BELOW_ANKLE + THICKNESS / 2)  # bottom face on the sole frame
    text = replace_collisions_with_boxes(text, {ln: (size, centre) for ln in SOLE_LINKS})
    path.write_text(text)
    return str(path)


def test_package_uris_are_resolved_and_soles_are_boxes(example_robot_urdf, tmp_path):
    import xml.etree.ElementTree as ET

    root = ET.parse(_talos_urdf_for_pybullet(example_robot_urdf, tmp_path / 't.urdf')).getroot()
    meshes = [m.get('filename') for m in root.iter('mesh')]
    assert meshes and all(os.path.isfile(m) for m in meshes)
    for link in root.findall('link'):
        if link.get('name') in SOLE_LINKS:
            (col,) = link.findall('collision')
            size = [float(s) for s in col.find('geometry/box').get('size').split()]
            np.testing.assert_allclose(size, [0.2, 0.13, THICKNESS])


def test_textures_are_resolved_too(tmp_path):
    pkg = tmp_path / 'share' / 'my_robot'
    (pkg / 'urdf').mkdir(parents=True)
    text = (
        '<robot name="r"><material name="m"><texture filename="package://my_robot/t.png"/>'
        '</material><link name="a"/></robot>'
    )
    out = resolve_package_uris(text, str(pkg / 'urdf' / 'r.urdf'))
    assert f'filename="{pkg}/t.png"' in out
    out = resolve_package_uris(text, '/elsewhere/r.urdf', {'my_robot': str(pkg)})
    assert f'filename="{pkg}/t.png"' in out


def test_a_missing_package_or_link_is_named():
    text = '<robot name="r"><link name="a"><visual><geometry>' \
        '<mesh filename="package://nowhere/m.stl"/></geometry></visual></link></robot>'
    with pytest.raises(ValueError, match="package 'nowhere' not found"):
        resolve_package_uris(text, '/tmp/r.urdf')
    with pytest.raises(ValueError, match="no link 'b'"):
        replace_collisions_with_boxes(text, {'b': ((1, 1, 1), (0, 0, 0))})


def test_talos_sways_its_com_in_pybullet(
    talos_standing, example_robot_urdf, com_sway_in_pybullet, tmp_path
):
    robot, c, com, q = _talos(talos_standing, 'daqp')
    urdf = _talos_urdf_for_pybullet(example_robot_urdf, tmp_path / 'talos.urdf')
    names = robot.get_joint_names()
    with SimServer(time_step=DT) as server:
        sim = server.insert_model_from_urdf_file(
            urdf, position=q[:3], orientation=q[3:7], fixed_base=False
        )
        by_name = sim.joint_map(names)
        sim.set_model_configuration(names, q[7:])
        soles0 = [sim.get_link_position(s) for s in SOLE_LINKS.values()]
        errors, failures = com_sway_in_pybullet(
            robot, c, com, server, sim, by_name, 10.0, AMPLITUDE, OMEGA
        )
        slide = max(
            np.linalg.norm(sim.get_link_position(s)[:2] - p0[:2])
            for s, p0 in zip(SOLE_LINKS.values(), soles0)
        )
        base_height = sim.get_world_to_base_transform()[2, 3]
    errors = np.asarray(errors)
    rms = float(np.sqrt(np.mean(errors**2)))
    settled = float(np.sqrt(np.mean(errors[int(round(1.0 / DT)):] ** 2)))
    print(
        f'pybullet: CoM rms {rms * 1e3:.3f} mm (after 1 s {settled * 1e3:.3f} mm), '
        f'slide {slide * 1e3:.3f} mm, base height {base_height - q[2]:+.4f} m, '
        f'failures {failures}'
    )
    assert failures == 0
    # measured 0.92 mm, nearly all of it in the first second: the reference sets off at
    # A omega = 0.16 m/s from a robot at rest; 3x margin
    assert rms <= 3e-3, f'CoM rms error {1000 * rms:.2f} mm'
    # then: measured 0.16 mm (PyBullet's contacts and the torque loop add to the kinematic run's
    # 0.03 mm); 3x margin
    assert settled <= 5e-4, f'CoM rms error after the first second {1000 * settled:.3f} mm'
    # measured 0.55 mm (PyBullet's soft contacts let the boxes creep as the load shifts); 3.6x
    assert slide < 2e-3, f'a sole slid {1000 * slide:.1f} mm'
    # measured 9.5 cm lower (the knees bend as the posture drifts); 1.6x: a fall drops it ~1 m
    assert base_height > q[2] - 0.15
