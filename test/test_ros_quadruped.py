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
The quadruped through the nodes.

Bridge (floating base, odom) + controller from config/quadruped_controller.yaml.
"""

import time

import numpy as np
import orca_ros as orca
from orca_ros.examples import quadruped as quad
from orca_ros.ros.launch_free import free_domain_id, Procs
from orca_ros.ros.probe import Probe


def test_stand_and_shift_through_the_nodes(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    robot = quad.make_robot()
    joints = robot.get_joint_names()
    home = np.array([0.0, 0.0, quad.STAND_HEIGHT])
    q0 = '[' + ', '.join(f'{v:.3f}' for v in quad.STAND_Q) + ']'
    procs.start(
        'orca_ros.ros.pybullet_bridge',
        '-p',
        'mode:=lockstep',
        '-p',
        'urdf_path:=quadruped.urdf',
        '-p',
        'floating_base:=true',
        '-p',
        f'initial_positions:={q0}',
        '-p',
        f'base_position:=[0.0, 0.0, {home[2] + 0.001:.4f}]',
        name='bridge',
    )
    procs.start(
        'orca_ros.ros.controller_node',
        '--params-file',
        orca.share_path('config', 'quadruped_controller.yaml'),
        '-p',
        'trigger:=joint_state',
        name='controller',
    )
    probe = Probe(domain, joints=joints)
    try:
        probe.wait_for(lambda: probe.sim_time() > 1.5, 90, 'the controller driving the quadruped')
        # standing: the base holds its pose
        with probe.lock:
            odom = list(probe.odom)
        assert odom, 'no odom from the bridge'
        stand = np.array([p for t, p, _ in odom if t > 0.5])
        assert np.abs(stand - home).max() < 2e-3
        # shift: a +-5 cm sinusoid streamed as target points with velocity/acceleration
        # feed-forward
        period, amp, duration = 2.0, 0.05, 5.0
        t0 = probe.sim_time()
        while probe.sim_time() < t0 + duration:
            s = probe.sim_time() - t0 + 0.001
            y, vy, ay = quad.sinusoid(s, amp, period, duration)
            probe.send_target_point('base', home + [0, y, 0], (0, vy, 0), (0, ay, 0))
            time.sleep(0.001)
        probe.wait_sim(0.3)
        with probe.lock:
            odom = list(probe.odom)
        shift = [(t - t0, p) for t, p, _ in odom if t0 + 0.01 < t < t0 + duration]
        ref = np.array(
            [home + [0, quad.sinusoid(s, amp, period, duration)[0], 0] for s, _ in shift]
        )
        pos = np.array([p for _, p in shift])
        assert np.ptp(pos[:, 1]) > 0.09  # the base did swing +-5 cm
        rms = np.sqrt(np.mean(np.sum((pos - ref) ** 2, axis=1)))
        print(
            f'nodes: base sinusoid rms {rms * 1e3:.2f} mm, standing max '
            f'{np.abs(stand - home).max() * 1e3:.2f} mm'
        )
        assert rms < 5e-3, f'base sinusoid through the nodes tracked with rms {rms * 1e3:.2f} mm'
        assert 'safe command' not in procs.log('controller')
    finally:
        probe.close()
        procs.stop()


def test_stale_odom_gives_the_safe_command(tmp_path):
    """
    Switch to the safe command when odom stops.

    A floating-base controller whose odom stops (joint states still coming) switches to the safe
    command and says why; the commands stay finite.
    """
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import JointState

    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    robot = quad.make_robot()
    joints = robot.get_joint_names()
    procs.start(
        'orca_ros.ros.controller_node',
        '--params-file',
        orca.share_path('config', 'quadruped_controller.yaml'),
        name='controller',
    )
    probe = Probe(domain, joints=joints)
    pub_odom = probe.node.create_publisher(Odometry, '/odom', 10)
    try:
        probe.wait_for(
            lambda: (
                probe.pub_state.get_subscription_count() > 0
                and pub_odom.get_subscription_count() > 0
            ),
            30,
            "the controller's state subscriptions",
        )

        def publish(with_odom):
            now = probe.node.get_clock().now().to_msg()
            js = JointState(
                name=joints, position=[float(v) for v in quad.STAND_Q], velocity=[0.0] * 12
            )
            js.header.stamp = now
            probe.pub_state.publish(js)
            if with_odom:
                od = Odometry()
                od.header.stamp = now
                od.pose.pose.position.z = float(quad.STAND_HEIGHT)
                od.pose.pose.orientation.w = 1.0
                pub_odom.publish(od)

        # discovery is not symmetric: the probe may see the subscription seconds before the
        # controller accepts its messages, so publish until the controller answers (a condition,
        # not a duration)
        t_end = time.time() + 60
        while len(probe.commands) < 100 and time.time() < t_end:
            publish(True)
            time.sleep(0.005)
        assert len(probe.commands) >= 100, 'the controller never answered'
        t_end = time.time() + 60
        while 'odom stale' not in procs.log('controller') and time.time() < t_end:
            publish(False)
            time.sleep(0.005)
        assert 'odom stale' in procs.log('controller'), procs.log('controller')[-2000:]
        # commands keep coming (the safe one), finite
        n = len(probe.commands)
        probe.wait_for(lambda: len(probe.commands) > n + 20, 60, 'commands after odom went stale')
        with probe.lock:
            cmds = np.array(probe.commands)
        assert np.all(np.isfinite(cmds))
    finally:
        probe.close()
        procs.stop()
