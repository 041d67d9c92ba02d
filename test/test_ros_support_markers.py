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
The controller's ``~/markers`` through the nodes: the quadruped standing, lockstep.

The markers of an instant carry the model's CoM at the state of that instant, the support
polygon of the four feet and one arrow per foot whose forces hold the robot's weight.
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples import quadruped as quad
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe

FORCE_SCALE = 0.001  # m/N, the arrows' length per newton


def _model():
    robot = orca.RobotModel('quadruped')
    robot.load_model_from_file(orca.share_path('urdf', 'quadruped.urdf'), floating_base=True)
    robot.set_base_frame('world')
    return robot


def test_markers_carry_the_com_the_support_polygon_and_the_contact_forces(tmp_path):
    from visualization_msgs.msg import Marker, MarkerArray

    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    robot = _model()
    joints = robot.get_joint_names()
    q0 = '[' + ', '.join(f'{v:.3f}' for v in quad.STAND_Q) + ']'
    procs.start('orca_ros.ros.pybullet_bridge', '-p', 'mode:=lockstep', '-p',
                'urdf_path:=quadruped.urdf', '-p', 'floating_base:=true', '-p',
                f'initial_positions:={q0}', '-p',
                f'base_position:=[0.0, 0.0, {quad.STAND_HEIGHT + 0.001:.4f}]', name='bridge')
    procs.start('orca_ros.ros.controller_node', '--params-file',
                orca.share_path('config', 'quadruped_controller.yaml'), '-p',
                'trigger:=joint_state', '-p', f'marker_force_scale:={FORCE_SCALE}',
                name='controller')
    probe = Probe(domain, joints=joints)
    got = []
    probe.node.create_subscription(MarkerArray, '/orca_controller/markers', got.append, 100)
    try:
        probe.wait_for(lambda: probe.sim_time() > 0.6, 120, 'the quadruped standing 0.6 s')

        def received():
            """Return the probe's states and base poses, and the markers after 0.5 s with both."""
            with probe.lock:
                states = {round(t, 6): q for t, q, _ in probe.states}
                odom = {round(t, 6): (p, o) for t, p, o in probe.odom}
            stamps = [round(_stamp(m), 6) for m in list(got)]
            return states, odom, sum(t > 0.5 and t in states and t in odom for t in stamps)

        # (waited for as many as are checked below: markers arrive at their own rate)
        probe.wait_for(lambda: received()[2] >= 3, 30, 'three marker arrays after 0.5 s')
        states, odom, _ = received()
        mg = robot.get_total_mass() * 9.81
        checked, com_err, force_err = 0, 0.0, 0.0
        for msg in got:
            t = round(_stamp(msg), 6)
            if t <= 0.5 or t not in states or t not in odom:
                continue
            by_ns = {}
            for m in msg.markers:
                by_ns.setdefault(m.ns, []).append(m)
            # the model's CoM at the state of that instant
            p, o = odom[t]
            T = np.eye(4)
            T[:3, :3] = _rotation(o)
            T[:3, 3] = p
            robot.set_robot_state(T, states[t], np.zeros(6), np.zeros(12), [0.0, 0.0, -9.81])
            com = by_ns['com'][0]
            assert com.header.frame_id == 'world' and com.type == Marker.SPHERE
            c = np.array([com.pose.position.x, com.pose.position.y, com.pose.position.z])
            com_err = max(com_err, np.linalg.norm(c - robot.get_center_of_mass()))
            # the polygon: the four feet, closed, around the CoM
            poly = by_ns['support_polygon'][0]
            pts = np.array([[v.x, v.y, v.z] for v in poly.points])
            feet = np.array([robot.get_frame_pose(f'{leg}_foot')[:3, 3]
                             for leg in ('FL', 'FR', 'HL', 'HR')])
            assert poly.type == Marker.LINE_STRIP and len(pts) == 5
            assert np.allclose(pts[0], pts[-1])
            for foot in feet:
                assert np.min(np.linalg.norm(pts[:4, :2] - foot[:2], axis=1)) < 1e-3
            assert pts[:, 0].min() < c[0] < pts[:, 0].max()
            assert pts[:, 1].min() < c[1] < pts[:, 1].max()
            # one arrow per foot, from the foot; the forces hold the weight
            arrows = by_ns['contact_forces']
            assert len(arrows) == 4 and all(a.type == Marker.ARROW for a in arrows)
            force = np.zeros(3)
            for a in arrows:
                start, end = (np.array([v.x, v.y, v.z]) for v in a.points)
                assert np.min(np.linalg.norm(feet - start, axis=1)) < 1e-3
                force += (end - start) / FORCE_SCALE
            force_err = max(force_err, abs(force[2] - mg) / mg)
            checked += 1
        print(f'{checked} marker arrays checked (t > 0.5 s): CoM within '
              f'{com_err * 1e3:.4f} mm of the model, contact forces sum to the weight '
              f'({mg:.1f} N) within {force_err * 100:.2f} %')
        assert checked >= 3
        assert com_err < 1e-3
        assert force_err < 0.02
        assert 'Traceback' not in procs.log('controller')
    finally:
        probe.close()
        procs.stop()


def _stamp(msg) -> float:
    s = msg.markers[0].header.stamp
    return s.sec + 1e-9 * s.nanosec


def _rotation(xyzw) -> np.ndarray:
    import pinocchio as pin

    x, y, z, w = xyzw
    return pin.Quaternion(w, x, y, z).normalized().matrix()
