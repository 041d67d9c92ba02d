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
A robot given as MJCF through the nodes: ``urdf_path`` names an MJCF file for both.

The shipped arm as MJCF (``mjcf/lwr.xml``) on ``mujoco_bridge`` with the shipped controller
configuration: a target 12 cm away reached. An MJCF robot on the PyBullet bridge, one the
parser refuses, or a joint the model lacks, is one line naming the cause and exit 1.
"""

import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest


def test_the_arm_as_mjcf_reaches_its_target_through_the_nodes(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    model = ('-p', 'urdf_path:=lwr.xml')
    procs.start_arm('lockstep', simulator='mujoco', bridge_args=model, controller_args=model)
    probe = Probe(domain)
    try:
        probe.wait_for(lambda: probe.sim_time() > 1.0, 120, 'the controller driving the arm')
        target = probe.send_ee_offset([0.1, -0.05, 0.05])
        probe.wait_for(lambda: np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3]) < 1e-4,
                       120, 'the target reached')
        for node in ('controller', 'bridge'):
            assert 'model ' + orca.share_path('mjcf', 'lwr.xml') in procs.log(node)
        assert int(probe.diagnostics.get('qp_failures', 0)) == 0
    finally:
        probe.close()
        procs.stop()


@pytest.mark.parametrize('case', ['mjcf_on_pybullet', 'unparsable', 'joint_pybullet',
                                  'joint_mujoco'])
def test_a_model_the_node_cannot_take_is_one_line_and_exit_1(tmp_path, case):
    """Also a joint in ``joints`` the model lacks, on either bridge."""
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    if case.startswith('joint_'):
        p = procs.start_arm_bridge('lockstep', '-p', 'joints:=[joint_0, nope]',
                                   '-p', 'initial_positions:=[0.0, 0.0]',
                                   simulator=case.split('_')[1])
        name, said = 'bridge', "cannot run: ValueError: model 'lwr' has no joint(s) ['nope']"
    elif case == 'mjcf_on_pybullet':
        p = procs.start_arm_bridge('lockstep', '-p', 'urdf_path:=lwr.xml')
        name, said = 'bridge', 'is MJCF: this world reads URDF (an MJCF robot runs on MuJoCo'
    else:
        bad = tmp_path / 'bad.xml'
        bad.write_text('<mujoco><worldbody><body name="a"><joint type="hinge"/>'
                       '<geom type="blob"/></body></worldbody></mujoco>')
        p = procs.start_arm_controller('lockstep', '-p', f'urdf_path:={bad}')
        name, said = 'controller', 'could not parse MJCF'
    try:
        procs.assert_refused(p, name, said)
    finally:
        procs.stop()
