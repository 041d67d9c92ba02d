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
An arm nobody tuned for on position or velocity servos, through the nodes (issue 39).

The UR5 of example-robot-data with the shipped config/lwr_controller.yaml, only the robot's names
(URDF, base frame, joints, hand frame ``tool0``, the posture's target) and ``command_interface``
changed, on the controller and on the bridge. Lockstep. The hand is sent to three targets, each
10 cm from the last. With a collision constraint (its defaults, the UR5's own SRDF) a ball of 5
cm radius stands where the third move passes. Measured on the simulated joints (the bridge's
joint_states); distances by coal on the URDF's own collision meshes at those states.
"""

import coal
import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
from orca_ros.sim import resolve_package_uris
import pinocchio as pin
import pytest
from visualization_msgs.msg import Marker, MarkerArray

URDF = 'ur_description/urdf/ur5_robot.urdf'
SRDF = 'ur_description/srdf/ur5.srdf'
JOINTS = ['shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint', 'wrist_1_joint',
          'wrist_2_joint', 'wrist_3_joint']
Q0 = [0.0, -1.3, 1.5, -1.8, -1.57, 0.0]  # the UR5's working posture, the hand pointing down
MOVES = ([0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, -0.1])  # each target 10 cm from the last
START = 0.6  # s of simulated time: the tasks' ramp (0.5 s) over, the arm holding
SETTLE = 2.0  # s of simulated time per target (10 cm along the node's trajectory: ~0.9 s)
RADIUS = 0.05  # the ball [m]
BELOW = 0.12  # its centre below the second target [m]: the third one 2 cm from it, inside
SAFETY = 0.02  # the collision constraint's default safety distance [m]
ROUNDING = 0.01  # its geometry's rounding of every body, the ball's too [m] (CollisionGeometry)
VELOCITY_CAP = 1.5  # [rad/s] the shipped velocity_limit's max (the URDF's: 3.15 and 3.2)
# the most the simulated arm lags the reference its servos track [m]: a servo critically damped
# at 20 Hz (the bridge's servo_frequency) lags a ramp by 2 v / w; v at most the node's Cartesian
# trajectory's 0.25 m/s. The constraint's bounds are the measured state's; the reference they
# move may be that far ahead of it
LAG = 2 * 0.25 / (2 * np.pi * 20.0)
CYCLE_TRAVEL = 0.25e-3  # [m] the hand's travel in one 1 ms cycle at 0.25 m/s


def _mm(errors) -> str:
    """Return distances [m] in mm, comma-separated."""
    return ', '.join(f'{e * 1e3:.2e}' for e in errors)


def _resolved(urdf, tmp_path):
    """Write the URDF with its meshes' package:// URIs as files (for PyBullet); its path."""
    path = tmp_path / 'ur5.urdf'
    with open(urdf) as fh:
        path.write_text(resolve_package_uris(fh.read(), urdf))
    return str(path)


class _Ur5:
    """
    The UR5's hand pose, and the distance of its collision shapes to a ball (coal).

    ``distance``: the URDF's own shapes (meshes); ``hull_distance``: their convex hulls, the shapes
    the collision constraint holds its distance on (each rounded by ROUNDING there, the ball too).
    """

    def __init__(self, urdf):
        self.robot = orca.RobotModel()
        self.robot.load_model_from_file(urdf)
        self.model = self.robot.model
        self.data = self.model.createData()
        self.gm = pin.buildGeomFromUrdf(self.model, urdf, pin.COLLISION)
        self.gd = pin.GeometryData(self.gm)
        self.ball = coal.Sphere(RADIUS)
        self.hulls, self.bounds = [], []  # and the bounding spheres (centre, radius)
        for g in self.gm.geometryObjects:
            g.geometry.computeLocalAABB()
            self.bounds.append((np.array(g.geometry.aabb_center), g.geometry.aabb_radius))
            if hasattr(g.geometry, 'buildConvexHull'):  # a mesh
                g.geometry.buildConvexHull(True, 'Qt')
                self.hulls.append(g.geometry.convex)
            else:
                self.hulls.append(g.geometry)

    def hand(self, q) -> np.ndarray:
        """Return tool0's pose (4x4) at q, in the base frame (base_link, the world's)."""
        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, dtype=float))
        return self.data.oMf[self.model.getFrameId('tool0')].homogeneous.copy()

    def least(self, qs, centre, hulls=False) -> float:
        """Return the least distance from the arm's shapes (all links) to the ball, over qs."""
        at = coal.Transform3s(np.eye(3), np.asarray(centre, dtype=float))
        best = np.inf
        for q in qs:
            pin.updateGeometryPlacements(self.model, self.data, self.gm, self.gd,
                                         np.asarray(q, dtype=float))
            for i, g in enumerate(self.gm.geometryObjects):
                # the bounding spheres' gap, a lower bound: no nearer than the least so far, skip
                c, r = self.bounds[i]
                if np.linalg.norm(self.gd.oMg[i].act(c) - centre) - r - RADIUS >= best:
                    continue
                res = coal.DistanceResult()
                coal.distance(self.hulls[i] if hulls else g.geometry,
                              coal.Transform3s(self.gd.oMg[i]), self.ball, at,
                              coal.DistanceRequest(), res)
                best = min(best, res.min_distance)
        return best


def _ball_marker(centre, ident=1, action=Marker.ADD):
    m = Marker()
    m.header.frame_id = 'world'
    m.ns, m.id, m.type, m.action = 'test', ident, Marker.SPHERE, action
    m.pose.position.x, m.pose.position.y, m.pose.position.z = (float(c) for c in centre)
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = 2 * RADIUS
    return m


def _run(example_robot_urdf, tmp_path, interface, with_ball=False):
    """
    Send the hand to the three targets, SETTLE s of simulated time each.

    Return (arm, targets, errors at the end of each move [m], states, ball centre or None,
    controller log, bridge log).
    """
    urdf = _resolved(example_robot_urdf(URDF), tmp_path)
    arm = _Ur5(urdf)
    start = arm.hand(Q0)
    targets = []
    for move in MOVES:
        T = (targets[-1] if targets else start).copy()
        T[:3, 3] += move
        targets.append(T)
    centre = targets[1][:3, 3] - [0.0, 0.0, BELOW] if with_ball else None
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    both = ('-p', f'command_interface:={interface}', '-p', f'urdf_path:={urdf}',
            '-p', f'joints:={JOINTS}')
    procs.start('orca_ros.ros.pybullet_bridge', '-p', 'mode:=lockstep',
                '-p', f'initial_positions:={Q0}', *both, name='bridge')
    collision = ()
    if with_ball:
        collision = (
            '-p', 'constraints.names:=[torque_limit, position_limit, velocity_limit, collision]',
            '-p', 'constraints.collision.type:=collision_avoidance',
            '-p', f'constraints.collision.srdf:={example_robot_urdf(SRDF)}',
        )
    procs.start_arm_controller(
        'lockstep', *both, '-p', 'base_frame:=base_link', '-p', 'tasks.ee.frame:=tool0',
        '-p', f'tasks.posture.target:={Q0}', *collision)
    probe = Probe(domain, joints=JOINTS)
    errors = []
    try:
        probe.wait_for(lambda: probe.sim_time() >= START, 120, 'the tasks ramped in')
        if with_ball:
            # one array: the ball and the DELETE of a marker that does not exist. The refusal of
            # the second in the controller's log tells the array, the ball with it, arrived
            pub = probe.node.create_publisher(MarkerArray, '/orca_controller/obstacles', 10)
            array = MarkerArray(markers=[_ball_marker(centre),
                                         _ball_marker(centre, 2, Marker.DELETE)])
            heard = "obstacle marker 'test/2' refused"
            probe.wait_for(lambda: pub.publish(array) or heard in procs.log('controller'), 60,
                           heard)
            line = "obstacle 'test/1' in the simulation"
            probe.wait_for(lambda: pub.publish(array) or line in procs.log('bridge'), 60, line)
        for T in targets:
            p0 = arm.hand(probe.last_state()[1])[:3, 3]
            way = (T[:3, 3] - p0) / np.linalg.norm(T[:3, 3] - p0)
            probe.send_target(
                'ee', T, until=lambda: (arm.hand(probe.last_state()[1])[:3, 3] - p0) @ way > 1e-3)
            t_sent = probe.sim_time()
            probe.wait_for(lambda: probe.sim_time() >= t_sent + SETTLE, 120,
                           f'{SETTLE} s of simulated time')
            errors.append(np.linalg.norm(arm.hand(probe.last_state()[1])[:3, 3] - T[:3, 3]))
        with probe.lock:
            states = list(probe.states)
        logs = procs.log('controller'), procs.log('bridge')
    finally:
        probe.close()
        procs.stop()
    return arm, targets, np.array(errors), states, centre, *logs


def _limits(arm, states):
    """Return (fastest joint's fraction of the shipped cap, of the URDF's, least room [rad])."""
    lo, hi = arm.robot.get_joint_position_limits()
    q = np.array([s[1] for s in states])
    v = np.array([s[2] for s in states])
    room = min((q - lo).min(), (hi - q).min())
    return (np.abs(v).max() / VELOCITY_CAP,
            (np.abs(v) / arm.robot.get_joint_velocity_limits()).max(), room)


@pytest.mark.parametrize('interface', ['position', 'velocity'])
def test_the_ur5_reaches_three_targets_within_its_limits(example_robot_urdf, tmp_path,
                                                         interface):
    """
    Each target within 1 mm; positions and speeds within the limits, at every state received.

    The speeds within the shipped configuration's cap (1.5 rad/s, below the URDF's limits).
    """
    arm, _, errors, states, _, log, bridge_log = _run(example_robot_urdf, tmp_path, interface)
    cap, urdf, room = _limits(arm, states)
    print(f'{interface}: hand {_mm(errors)} mm from its '
          f'targets; fastest joint at {cap:.2f} of the cap ({urdf:.2f} of its URDF limit); '
          f'least room to a position limit {room:.3f} rad; {len(states)} states')
    assert (errors < 1e-3).all()
    assert room > 0.0
    assert cap <= 1.0
    assert 'safe command' not in log, log[-2000:]
    assert 'rejected' not in bridge_log, bridge_log[-2000:]


def test_the_ur5_on_position_servos_keeps_away_from_a_ball(example_robot_urdf, tmp_path):
    """
    The third move heads into a ball: the hand stops short, held at the safety distance.

    The ball (5 cm) stands under the second target, its top 7 cm below the hand's flange there;
    the third target, 10 cm down, is 2 cm from its centre. The first two moves pass beside it and
    reach their targets. The constraint holds its distance (the convex hulls', each rounded by
    ROUNDING, the ball too) at SAFETY or more: the meshes, inside their hulls, stay SAFETY + 2
    ROUNDING away, less the servos' LAG. Pulled on towards its target, the hand rests with that
    distance at SAFETY.
    """
    arm, targets, errors, states, centre, log, bridge_log = _run(
        example_robot_urdf, tmp_path, 'position', with_ball=True)
    # without the constraint the hand would go into the ball: its target is inside
    assert np.linalg.norm(targets[2][:3, 3] - centre) < RADIUS
    least = arm.least([q for _, q, _ in states], centre)
    held = arm.least([states[-1][1]], centre, hulls=True) - 2 * ROUNDING
    cap, urdf, room = _limits(arm, states)
    end = states[-1][0]
    still = max(np.abs(v).max() for t, _, v in states if t >= end - 0.5)
    print(f'hand {_mm(errors)} mm from its targets')
    print(f'least distance of the meshes to the ball {least * 1e3:.2f} mm (asserted >= '
          f'{(SAFETY + 2 * ROUNDING - LAG) * 1e3:.2f}); the distance the constraint holds, at '
          f'the end {held * 1e3:.3f} mm; last 0.5 s at {still:.1e} rad/s at most')
    print(f'fastest joint at {cap:.2f} of the cap ({urdf:.2f} of its URDF limit); least room to '
          f'a position limit {room:.3f} rad')
    assert (errors[:2] < 1e-3).all()
    # stopped short: the flange (tool0) SAFETY or more from the ball, as the meshes; its target
    # 3 cm inside it
    assert errors[2] > RADIUS - np.linalg.norm(targets[2][:3, 3] - centre) + SAFETY
    assert least >= SAFETY + 2 * ROUNDING - LAG
    assert abs(held - SAFETY) <= 2 * CYCLE_TRAVEL
    assert still < 1e-3
    assert room > 0.0
    assert cap <= 1.0
    assert 'safe command' not in log, log[-2000:]
    assert 'rejected' not in bridge_log, bridge_log[-2000:]
