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
"""A controller started without a URDF takes it from the robot_description the bridge publishes."""

import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe


def test_controller_runs_on_the_bridges_robot_description(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    # the parameter file names lwr.urdf: cleared here, so nothing but the topic gives the URDF
    procs.start_arm('lockstep', controller_args=('-p', "urdf_path:=''"))
    probe = Probe(domain)
    try:
        procs.wait_log('controller', 'URDF from /robot_description', timeout=60)
        probe.wait_for(lambda: probe.sim_time() > 1.0, 60, 'the controller driving the bridge')
        target = probe.ee_pose()
        target[:3, 3] += [0.05, -0.05, 0.05]
        probe.send_target('ee', target, until=probe.moved_towards(target))
        probe.wait_sim(3.0)
        err = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
        assert err < 1e-3, f'{err * 1e3:.2f} mm from the target'
        log = procs.log('controller')
        assert 'no urdf_path or robot_description parameter: waiting on /robot_description' in log
        assert 'Traceback' not in log
    finally:
        probe.close()
        procs.stop()
