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
Obstacles on ``~/obstacles`` (MarkerArray) through the nodes: the arm yields to a ball.

The shipped lwr configuration in lockstep, plus a collision constraint (defaults). Distances are
measured independently: coal on the URDF's own collision shapes at the simulator's states.
"""

import coal
from geometry_msgs.msg import Point
import numpy as np
import orca_ros as orca
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pinocchio as pin
import pytest
from visualization_msgs.msg import Marker, MarkerArray

RADIUS, SPEED = 0.05, 0.3  # the ball [m], its speed towards the hand [m/s]
SAFETY = 0.02  # the constraint's default
DT = 0.001  # the bridge's control period: one simulated step per command in lockstep
RELAY = '/probe/relayed_commands'


def _marker(centre=(0.0, 0.0, 0.0), action=Marker.ADD, kind=Marker.SPHERE, scale=2 * RADIUS,
            frame='world', ns='test', ident=1, stamp=None):
    m = Marker()
    m.header.frame_id = frame
    if stamp is not None:  # the instant of the pose (simulated time)
        m.header.stamp.sec, m.header.stamp.nanosec = int(stamp), int(round(stamp % 1.0 * 1e9))
    m.ns, m.id, m.type, m.action = ns, ident, kind, action
    m.pose.position = Point(x=float(centre[0]), y=float(centre[1]), z=float(centre[2]))
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = float(scale)
    return m


class _Distance:
    """Least distance from the arm's URDF collision shapes to a ball (coal, on a state)."""

    def __init__(self):
        robot = orca.RobotModel()
        robot.load_model_from_file(orca.default_urdf_path())
        self.model = robot.model
        self.data = self.model.createData()
        self.gm = pin.buildGeomFromUrdf(self.model, orca.default_urdf_path(), pin.COLLISION)
        self.gd = pin.GeometryData(self.gm)
        self.ball = coal.Sphere(RADIUS)

    def hand(self, q):
        """Return the position of the arm's last link (the controller's task frame) at q."""
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self.model.getFrameId('link_7')].translation.copy()

    def __call__(self, q, centre):
        pin.updateGeometryPlacements(self.model, self.data, self.gm, self.gd, q)
        at = coal.Transform3s(np.eye(3), np.asarray(centre, dtype=float))
        best = np.inf
        for i, g in enumerate(self.gm.geometryObjects):
            if g.parentJoint == 0:
                continue  # the base, welded to the world
            r = coal.DistanceResult()
            coal.distance(g.geometry, coal.Transform3s(self.gd.oMg[i]), self.ball, at,
                          coal.DistanceRequest(), r)
            best = min(best, r.min_distance)
        return best


def _start_arm_with_collision(procs, *args, simulator='pybullet'):
    """Start the shipped lwr configuration in lockstep, plus a collision constraint (defaults)."""
    procs.start_arm(
        'lockstep',
        simulator=simulator,
        controller_args=(
            '-p', 'constraints.names:=[torque_limit, position_limit, velocity_limit, collision]',
            '-p', 'constraints.collision.type:=collision_avoidance',
            *args,
        ),
    )


def test_the_arm_yields_to_a_ball_and_returns_when_it_is_deleted(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    # the probe relays the commands: the loop advances one simulated step per command it
    # forwards, and the ball's pose for the next step goes out before each (its pose on time
    # whatever the machine's load; from the probe's own, lagging copy of the simulated time, a
    # loaded machine's poses reached the controller up to 170 ms late, past max_extrapolation)
    _start_arm_with_collision(procs, '-p', f'command_topic:={RELAY}')
    probe = Probe(domain, relay_from=RELAY)
    pub = probe.node.create_publisher(MarkerArray, '/orca_controller/obstacles', 10)
    distance = _Distance()

    def send(*markers):
        pub.publish(MarkerArray(markers=list(markers)))

    try:
        probe.wait_sim(1.0, 120)  # the tasks ramp in (0.5 s): the arm holds its pose
        hand0 = probe.ee_pose()[:3, 3].copy()
        # bad markers first: each refused with its cause, the controller unharmed
        bad = [
            (_marker(kind=Marker.ARROW, ident=2), 'is not SPHERE, CUBE or CYLINDER'),
            (_marker(centre=(np.nan, 0.0, 0.0), ident=3), 'NaN'),
            (_marker(scale=0.0, ident=4), 'not > 0'),
            (_marker(frame='no_such_link', ident=5), "unknown frame 'no_such_link'"),
            (_marker(action=Marker.DELETE, ident=6), 'does not exist'),
        ]
        for m, cause in bad:  # sent until heard (the first may precede discovery's match)
            line = f"obstacle marker 'test/{m.id}' refused: "
            probe.wait_for(lambda: send(m) or line in procs.log('controller'), 60, line)
            assert cause in procs.log('controller'), (cause, procs.log('controller')[-2000:])
        # the ball comes at the hand from the side (y: across the arm's plane) at 0.3 m/s, from
        # 0.25 m away, goes 0.1 m past where the hand was and stops there (its velocity drops
        # to 0 in one step)
        start = hand0 - [0.0, 0.25, 0.0]
        t0 = probe.sim_time()

        def ball(t):
            return start + [0.0, min(SPEED * max(t - t0, 0.0), 0.35), 0.0]

        sent = [t0]

        def pose_next_step(answered):
            # the instant the command being relayed leads to: one step after the state it
            # answers (the same instant again for a state announced again)
            t = answered + DT
            send(_marker(ball(t), stamp=t))
            sent.append(t)

        probe.relay_hook = pose_next_step
        probe.wait_for(lambda: probe.sim_time() > t0 + 1.6, 300, "the ball's pass")
        probe.relay_hook = None
        assert not probe.relay_errors, probe.relay_errors
        with probe.lock:
            states = [s for s in probe.states if t0 <= s[0] <= sent[-1]]
        least = min(distance(q, ball(stamp)) for stamp, q, _ in states)
        # how far the hand went from where it held while the ball passed through that place
        moved = max(np.linalg.norm(distance.hand(q) - hand0) for _, q, _ in states)
        step = probe.max_torque_step(t0, probe.sim_time())
        print(f'least distance {least * 1e3:.1f} mm; the hand yielded {moved * 1e3:.0f} mm; '
              f'largest torque step {step:.2f} Nm')
        assert least >= SAFETY - 2e-3
        assert moved > 0.05  # it did yield: the ball passes where the hand was
        # smooth as pairs enter and leave, and as the ball stops (its velocity drops to 0 in one
        # marker): 10-22 Nm in one cycle before the bounds relaxed at a bounded rate
        assert step <= 2.0, f'{step:.2f} Nm in one cycle'
        # DELETE: back to where it held
        t1 = probe.sim_time()
        send(_marker(action=Marker.DELETE))
        probe.wait_sim(3.0, 120)
        back = np.linalg.norm(probe.ee_pose()[:3, 3] - hand0)
        step = probe.max_torque_step(t1, probe.sim_time())
        print(f'after DELETE: {back * 1e3:.2f} mm from the held pose; largest torque step '
              f'{step:.2f} Nm')
        assert back < 1e-3
        # the ball's bounds relax away: 18-50 Nm in one cycle when they vanished with it, 5.8-8.5
        # measured now (issue 21's 2 Nm is for pairs entering and leaving, asserted above; a
        # guard here, not met at 2)
        assert step < 15.0, f'{step:.2f} Nm in one cycle'
        assert probe.diagnostics.get('_message') == 'controlling'
    finally:
        probe.close()
        procs.stop()


@pytest.mark.parametrize('simulator', ['pybullet', 'mujoco'])
def test_an_absurd_obstacle_is_refused_by_both_nodes_and_the_arm_holds(tmp_path, simulator):
    """
    A ball of 100 m round the base (metres for centimetres) is refused, named, by both nodes.

    The controller's constraint refuses an obstacle deeper than max_depth into the moving links
    (kept, its rows asked every link to come out of it: the lwr's joints thrown at the torque
    limits, 1 rad/s in 15 cycles, before the QP had no solution; once, the hand 826 mm away when
    control came back), the simulator one that would overlap the links. The arm holds where it
    was: no failed cycle, the hand within 1e-3 mm. A ball of 5 cm beside the arm is taken after.
    """
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    _start_arm_with_collision(procs, simulator=simulator)
    probe = Probe(domain)
    pub = probe.node.create_publisher(MarkerArray, '/orca_controller/obstacles', 10)
    try:
        t_start = probe.sim_time()

        def at_rest():
            with probe.lock:
                if not probe.states:
                    return False
                t_last = probe.states[-1][0]
                recent = [v for t, _, v in probe.states if t >= t_last - 0.5]
            return (t_last > t_start + 1.5 and len(recent) > 1
                    and max(np.abs(v).max() for v in recent) < 1e-3)

        probe.wait_for(at_rest, 120, 'the arm at rest')
        hand0 = probe.ee_pose()[:3, 3].copy()
        t0 = probe.sim_time()
        absurd = MarkerArray(markers=[_marker(scale=200.0, ident=7)])
        refused = "obstacle marker 'test/7' refused: it would go 99"
        probe.wait_for(lambda: pub.publish(absurd) or refused in procs.log('controller'), 60,
                       refused)
        line = [x for x in procs.log('controller').splitlines() if refused in x][-1]
        print(line)
        assert "mm into the robot ('link_" in line and 'deeper than max_depth (100 mm)' in line
        simulated = "obstacle marker 'test/7' not simulated: it would go "
        probe.wait_for(lambda: simulated in procs.log('bridge'), 60, simulated)
        probe.wait_sim(1.0, 120)
        # a ball 30 cm from the hand: taken, in both
        beside = MarkerArray(markers=[_marker(centre=hand0 + [0.0, 0.3, 0.0], ident=8)])
        taken = "obstacle 'test/8' in the simulation"
        probe.wait_for(lambda: pub.publish(beside) or taken in procs.log('bridge'), 60, taken)
        probe.wait_sim(0.5, 120)
        with probe.lock:
            efforts = np.array([e for t, e in probe.efforts if t >= t0])
            hands = [probe.ee_pose(q)[:3, 3] for t, q, _ in probe.states if t >= t0]
        moved = max(np.linalg.norm(h - hand0) for h in hands)
        print(f'{len(efforts)} commands, largest {np.abs(efforts).max():.1f} Nm; the hand at most '
              f'{moved * 1e3:.2e} mm from where it held over {len(hands)} states')
        assert np.isfinite(efforts).all()
        assert moved < 1e-6
        log = procs.log('controller')
        assert 'safe command' not in log and "'test/8' refused" not in log, log[-2000:]
        assert int(probe.diagnostics.get('qp_failures', 0)) == 0
    finally:
        probe.close()
        procs.stop()


@pytest.mark.parametrize('simulator', ['pybullet', 'mujoco'])
def test_the_bridge_puts_the_obstacles_in_the_simulation(tmp_path, simulator):
    """
    A wall published on the controller's topic stops the hand physically; DELETE frees it.

    The controller here has no collision constraint: only the simulator knows the wall. Its
    target 15 cm beyond the wall is not reached while the wall stands, and is once it is deleted.
    """
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm('lockstep', simulator=simulator)
    probe = Probe(domain)
    pub = probe.node.create_publisher(MarkerArray, '/orca_controller/obstacles', 10)

    def send(m):
        pub.publish(MarkerArray(markers=[m]))

    try:
        probe.wait_sim(1.0, 120)
        T = probe.ee_pose()
        hand0 = T[:3, 3].copy()
        wall = _marker(hand0 + [0.0, 0.12, 0.0], kind=Marker.CUBE, scale=0.3)
        wall.scale.y = 0.02  # 30 x 2 x 30 cm, across the way along y
        line = "obstacle 'test/1' in the simulation"
        probe.wait_for(lambda: send(wall) or line in procs.log('bridge'), 60, line)
        target = T.copy()
        target[1, 3] += 0.15
        probe.send_target('ee', target, until=probe.moved_towards(target, 0.01))
        probe.wait_sim(3.0, 120)
        blocked = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
        gone = "obstacle 'test/1' removed from the simulation"
        probe.wait_for(lambda: send(_marker(action=Marker.DELETE)) or gone in procs.log('bridge'),
                       60, gone)
        probe.wait_sim(3.0, 120)
        free = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
        print(f'hand from its target: {blocked * 1e3:.1f} mm behind the wall, {free * 1e3:.2f} mm '
              'once it is deleted')
        assert blocked > 0.03
        assert free < 1e-3
    finally:
        probe.close()
        procs.stop()
