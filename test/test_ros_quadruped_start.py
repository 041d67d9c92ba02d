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
A floating-base robot started as docs/ros_interface.md starts it (issue 37).

The bridge free running (not lockstep, not paused) with the robot placed 1 mm above its feet, the
controller started 5 s of simulated time later with the shipped config/quadruped_controller.yaml.
The bridge holds the base where it was placed until the first command (``hold_base_until_command``)
and releases it over ``base_release``: within 3 s of simulated time after the controller's first
command the trunk stands at its configured height, has not travelled nor tilted, and no cycle
failed: the shipped quadruped, and Go1 and Solo12 of example-robot-data with the shipped YAML's
tasks and contacts on their own frames and standing poses. Without the hold (the counterfactual)
the trunk sinks while nobody controls it; a controller started on the robot lying so (in lockstep:
the controller's behaviour, not the machine's CPU) finds its configured target far away and goes
there along the target's trajectory. Simulated time is the bridge's ``/clock`` (free running
stamps its states with its node clock).
"""

import re
import threading
import time

import numpy as np
import orca_ros as orca
from orca_ros.examples import quadruped_robot as qr
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
import pytest

GAP = 0.001  # the docs place the trunk 1 mm above standing (0.327 m for the shipped 0.3259 m)
WAIT = 5.0  # s of simulated time before the controller starts
SETTLE = 3.0  # s of simulated time after its first command
# s of simulated time more for a controller starved of CPU near SETTLE: the bridge's hold (gravity
# + damping) lets a standing trunk sink about 1 cm in 0.1 s, which the controller then undoes
GRACE = 2.0
# the bridge's record of the command that releases the base: simulated time, where the base was
RELEASE = re.compile(
    r'first effort command at t = (\S+) s \(simulated\), the base at \[([^\]]*)\] m'
)


class Observer:
    """
    One light node: the bridge's ``/clock``, ``odom`` and ``/diagnostics``.

    ``joint_states`` too when asked (the sink's joints: one more 1 kHz topic). Every odom sample
    is stamped with the simulated time heard last (free running stamps states with the bridge's
    node clock, not the simulated one). Best effort, depth 1 for the 1 kHz
    topics: a slow observer skips samples, it does not load the machine.
    """

    def __init__(self, domain: int, joint_states: bool = False):
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from nav_msgs.msg import Odometry
        from orca_ros.ros.common import STATE_QOS
        from rclpy.executors import SingleThreadedExecutor
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import JointState

        self.rclpy, self.lock = rclpy, threading.Lock()
        self.now, self.odom, self.diagnostics = -1.0, [], {}
        self.joint_positions = None  # the last joint state's
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = node = rclpy.create_node('observer', context=self.context)
        node.create_subscription(Clock, '/clock', self._on_clock, STATE_QOS)
        node.create_subscription(Odometry, '/odom', self._on_odom, STATE_QOS)
        node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diagnostics, 10)
        if joint_states:  # one more 1 kHz topic: only where the joints are wanted (the sink)
            node.create_subscription(JointState, '/joint_states', self._on_joints, STATE_QOS)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(node)
        self._stop = False
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _on_clock(self, m):
        self.now = max(self.now, m.clock.sec + m.clock.nanosec * 1e-9)

    def _on_odom(self, m):
        p, o = m.pose.pose.position, m.pose.pose.orientation
        with self.lock:
            self.odom.append((self.now, np.array([p.x, p.y, p.z]), np.array([o.x, o.y, o.z, o.w])))

    def _on_joints(self, m):
        with self.lock:
            self.joint_positions = np.array(m.position)

    def _on_diagnostics(self, m):
        for st in m.status:
            with self.lock:
                self.diagnostics = {kv.key: kv.value for kv in st.values}

    def _spin(self):
        while not self._stop and self.context.ok():
            self.executor.spin_once(timeout_sec=0.05)

    def wait_for(self, predicate, timeout: float, what: str):
        """Wait until ``predicate()`` (a condition; ``timeout`` only bounds a hung run)."""
        t_end = time.time() + timeout
        while not predicate():
            if time.time() > t_end:
                raise AssertionError(f'timed out after {timeout} s waiting for {what}')
            time.sleep(0.02)

    def poses(self, t0=-np.inf, t1=np.inf):
        """Odometry samples (simulated time, position, quaternion xyzw) with t0 <= t <= t1."""
        with self.lock:
            return [s for s in self.odom if t0 <= s[0] <= t1]

    def close(self):
        self._stop = True
        self.thread.join(timeout=5)
        self.node.destroy_node()
        self.rclpy.shutdown(context=self.context)


def _vector(values) -> str:
    return '[' + ', '.join(f'{float(v):.6f}' for v in values) + ']'


def _tilt(quat_xyzw) -> float:
    """Angle between the trunk's z axis and the world's [rad]."""
    x, y, _, _ = quat_xyzw
    return float(np.arccos(np.clip(1.0 - 2.0 * (x * x + y * y), -1.0, 1.0)))


def start_bridge(procs, quad, joints, *args, simulator='pybullet'):
    """Start the bridge as the docs do: free running, the trunk GAP above standing."""
    return procs.start(
        f'orca_ros.ros.{simulator}_bridge',
        '-p', f'urdf_path:={quad.urdf}',
        '-p', 'floating_base:=true',
        '-p', f'joints:={list(joints)}',
        '-p', f'base_position:={_vector(quad.home + [0.0, 0.0, GAP])}',
        '-p', f'base_orientation:={_vector(quad.q[3:7])}',
        '-p', f'initial_positions:={_vector(quad.joints)}',
        '-p', 'publish_clock:=true',
        *args,
        name='bridge',
    )


def shipped_quadruped(example_robot_urdf, tmp_path):
    """Return the shipped quadruped standing and config/quadruped_controller.yaml."""
    return qr.shipped(), orca.share_path('config', 'quadruped_controller.yaml')


# example-robot-data's: (URDF, SRDF (its 'standing' pose), foot radius (None: the URDF's sphere))
OTHERS = {
    'go1': ('go1_description/urdf/go1.urdf', 'go1_description/srdf/go1.srdf', None),
    # the foot is a mesh, the convex hull of a 16 mm ball centred on the frame
    'solo12': ('solo_description/robots/solo12.urdf', 'solo_description/srdf/solo.srdf', 0.016),
}


def other_quadruped(which):
    """Make (example_robot_urdf, tmp_path) -> that robot standing and the shipped YAML for it."""

    def make(example_robot_urdf, tmp_path):
        import yaml
        from orca_ros.sim import resolve_package_uris

        urdf, srdf, foot_radius = OTHERS[which]
        urdf = example_robot_urdf(urdf)
        path = tmp_path / f'{which}.urdf'  # the meshes' package:// URIs as files, for PyBullet
        with open(urdf) as fh:
            path.write_text(resolve_package_uris(fh.read(), urdf))
        quad = qr.from_urdf(str(path), example_robot_urdf(srdf), foot_radius=foot_radius)
        robot = orca.RobotModel()
        robot.load_model_from_file(quad.urdf, floating_base=True)
        with open(orca.share_path('config', 'quadruped_controller.yaml')) as fh:
            cfg = yaml.safe_load(fh)
        p = cfg['orca_controller']['ros__parameters']
        p['urdf_path'], p['joints'] = quad.urdf, robot.get_joint_names()
        p['tasks']['base'].update(frame=quad.trunk, target_position=quad.home.tolist())
        p['tasks']['posture']['target'] = quad.joints.tolist()
        for leg, foot in quad.feet.items():
            p['constraints'][f'{leg}_contact']['frame'] = foot
        params = tmp_path / f'{which}_controller.yaml'
        params.write_text(yaml.safe_dump(cfg))
        return quad, str(params)

    return make


def released(procs):
    """
    Return the bridge's record of its first command: (simulated time, base position), or None.

    The bridge's, not an observer's: a third node hears the first command late (its discovery of
    the controller, its share of the CPU) or not at all (best effort), and the trunk, released,
    has moved by then.
    """
    m = RELEASE.search(procs.log('bridge'))
    if m is None:
        return None
    return float(m.group(1)), np.array([float(v) for v in m.group(2).split(',')])


def start_as_documented(tmp_path, quad, params, hold='true', controller=True,
                        simulator='pybullet', until=None):
    """
    Start the bridge, WAIT s (simulated) later the controller; observe SETTLE s past its start.

    The controller's start is its first command (its process takes wall-clock seconds to load),
    as the bridge recorded it. ``until`` (a condition on the observer): past SETTLE, observe on
    until it holds, GRACE s more at most. Returns the observer (closed, its records kept), the
    controller's and the bridge's logs and the bridge's record of the release (:func:`released`;
    None without the controller).
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(quad.urdf, floating_base=True)
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    start_bridge(procs, quad, robot.get_joint_names(), '-p', f'hold_base_until_command:={hold}',
                 simulator=simulator)
    obs = Observer(domain, joint_states=not controller)
    try:
        obs.wait_for(lambda: obs.now >= WAIT and obs.poses()
                     and (controller or obs.joint_positions is not None),
                     120, f'{WAIT} s simulated')
        if not controller:
            return obs, '', None
        procs.start(
            'orca_ros.ros.controller_node', '--params-file', params, name='controller'
        )
        obs.wait_for(lambda: released(procs) is not None, 120, "the controller's first command")
        release = released(procs)
        obs.wait_for(lambda: obs.now >= release[0] + SETTLE, 120, f'{SETTLE} s simulated')
        if until is not None:
            obs.wait_for(lambda: until(obs) or obs.now >= release[0] + SETTLE + GRACE, 120,
                         f'{SETTLE + GRACE} s simulated')
        with obs.lock:
            obs.diagnostics = {}
        obs.wait_for(lambda: obs.diagnostics, 30, 'a diagnostics report')
        return obs, procs.log('controller') + procs.log('bridge'), release
    finally:
        obs.close()
        procs.stop()


ROBOTS = {'quadruped': shipped_quadruped, 'go1': other_quadruped('go1'),
          'solo12': other_quadruped('solo12')}


def settled(obs):
    """
    Return the trunk's median position and tilt over the last 0.5 s observed.

    The median: a sag of a moment the controller was starved of CPU (stale state, the safe
    command) aside.
    """
    last = obs.poses(obs.poses()[-1][0] - 0.5)
    tilt = float(np.median([_tilt(o) for *_, o in last]))
    return np.median([p for _, p, _ in last], axis=0), tilt


def level_tolerance(quad) -> float:
    """
    Return the tilt that moves a side's feet by GAP / 2 from the centre's height [rad].

    The tilt about the long axis over the narrow spread of the feet w: GAP / w, the level a trunk
    standing within GAP / 2 of its height on its four feet keeps.
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(quad.urdf, floating_base=True)
    robot.set_base_frame('world')
    robot.set_configuration(quad.q, np.zeros(robot.model.nv))
    feet = np.array([robot.get_frame_pose(f)[:3, 3] for f in quad.feet.values()])
    return GAP / float(np.ptp(feet[:, :2], axis=0).min())


@pytest.mark.parametrize('which, simulator', [(w, 'pybullet') for w in sorted(ROBOTS)]
                         + [('quadruped', 'mujoco')])
def test_a_quadruped_stands_when_started_as_documented(example_robot_urdf, tmp_path, which,
                                                       simulator):
    """
    Held until the controller's first command, then standing at its target, level, in place.

    The trunk is placed GAP above its target: standing at it, not where placed, is within GAP / 2,
    SETTLE s after the first command (GRACE s more if the controller was starved of CPU then: the
    bridge's hold sags the trunk, see GRACE). 5 cm and 5 degrees tell a robot that stood up in
    place from the lurch of issue 37. On MuJoCo too (the shipped quadruped here; Go1 and Solo12
    were run when the crane was fixed): its crane is a bounded wrench, its contacts MuJoCo's.
    """
    quad, params = ROBOTS[which](example_robot_urdf, tmp_path)

    def standing(obs):
        return abs(settled(obs)[0][2] - quad.home[2]) < GAP / 2

    obs, log, (t1, held) = start_as_documented(tmp_path, quad, params, simulator=simulator,
                                               until=standing)
    placed = quad.home + [0.0, 0.0, GAP]
    run = obs.poses(t1)
    pos = np.array([p for _, p, _ in run])
    travel = float(np.linalg.norm(pos[:, :2] - placed[:2], axis=1).max())
    tilt = max(_tilt(o) for _, _, o in run)
    height = settled(obs)[0][2]
    diagnostics = obs.diagnostics
    print(
        f'{which}: at the first command (t = {t1:.2f} s) the trunk '
        f'{(held[2] - placed[2]) * 1e3:+.3f} mm from where placed; '
        f'{obs.poses()[-1][0] - t1:.2f} s later '
        f'{(height - quad.home[2]) * 1e3:+.3f} mm from its target ({quad.home[2] * 1e3:.1f} mm), '
        f'travel {travel * 1e3:.2f} mm, tilt '
        f"{np.degrees(tilt):.2f} deg, failed cycles {diagnostics['qp_failures']}, cycles with "
        f"relaxed contacts {diagnostics['contacts_relaxed_cycles']}"
    )
    # what the logs said went wrong, if anything did (a stalled controller: the bridge's hold)
    said = '\n'.join(x for x in log.splitlines() if '[WARN]' in x or '[ERROR]' in x)
    assert np.linalg.norm(held - placed) < GAP / 2, 'the base was not held where placed'
    # measured 0.03-0.04 mm off the target (the contacts' compliance)
    assert abs(height - quad.home[2]) < GAP / 2, said
    # measured: at most 4 mm, 2 degrees (a command missed on a busy machine); issue 37: 0.68 m, 31
    assert travel < 0.05, said
    assert tilt < np.radians(5.0), said
    assert diagnostics['qp_failures'] == '0', said
    assert 'no QP solution' not in log


@pytest.fixture(scope='module')
def sunk(tmp_path_factory):
    """
    Return the shipped quadruped WAIT s (simulated) after placed: no hold, no controller.

    (quad, trunk position, trunk orientation xyzw, joint positions in the model's order).
    """
    tmp = tmp_path_factory.mktemp('sink')
    quad, _ = shipped_quadruped(None, tmp)
    obs, _, _ = start_as_documented(tmp, quad, None, hold='false', controller=False)
    _, position, orientation = obs.poses()[-1]
    return quad, position, orientation, obs.joint_positions


def test_without_the_hold_the_trunk_sinks(sunk):
    """
    The counterfactual: ``hold_base_until_command:=false``, nobody controlling for WAIT s.

    Gravity compensation of the joints alone lets the trunk sink: below half its standing height.
    """
    quad, position, _, _ = sunk
    print(f'without the hold: the trunk at {position[2] * 1e3:.1f} mm after {WAIT} s')
    assert position[2] < quad.home[2] / 2  # measured: 50 mm, its belly on the floor


def test_a_lying_quadruped_gets_up_along_its_trajectory(sunk, tmp_path):
    """
    Started on a trunk lying on the floor, the controller moves it to its target without a lurch.

    The robot is placed as the counterfactual above left it (trunk on the floor, legs folded) and
    run in lockstep (``trigger: joint_state``, every simulated millisecond commanded): what is
    asserted is the controller's, not a busy machine's. The configured base target is far away
    (the trunk sank and slid back): the node starts its trajectory from the measured state and
    says so. The trunk never gets 5 cm further from the target than it started (the documented
    start's bound; a step of the target threw it past it), and stands at it, level. Not asserted
    here: the tilt while it rises, and the cycles that may fail as it starts to rise (the feet
    cannot carry a trunk the floor carries: the knees near their limits, position_limit and the
    contacts' existence conditions); the documented start asserts both.
    """
    quad, position, orientation, joints = sunk
    robot = orca.RobotModel()
    robot.load_model_from_file(quad.urdf, floating_base=True)
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    start_bridge(
        procs, quad, robot.get_joint_names(), '-p', 'mode:=lockstep',
        '-p', f'base_position:={_vector(position)}',
        '-p', f'base_orientation:={_vector(orientation)}',
        '-p', f'initial_positions:={_vector(joints)}',
    )
    obs = Observer(domain)
    try:
        procs.start(
            'orca_ros.ros.controller_node', '--params-file', shipped_quadruped(None, tmp_path)[1],
            '-p', 'trigger:=joint_state', name='controller',
        )
        # lockstep: simulated time starts with the controller's first command
        obs.wait_for(lambda: obs.now >= SETTLE, 300, f'{SETTLE} s simulated')
        with obs.lock:
            obs.diagnostics = {}
        obs.wait_for(lambda: obs.diagnostics, 30, 'a diagnostics report')
        log = procs.log('controller')
    finally:
        obs.close()
        procs.stop()
    run = obs.poses()
    off = np.array([np.linalg.norm(p[:2] - quad.home[:2]) for _, p, _ in run])
    end, tilt = settled(obs)
    print(
        f'lying: {off[0] * 1e3:.1f} mm beside the target, {(run[0][1][2]) * 1e3:.1f} mm high; '
        f'{SETTLE} s later {(end[2] - quad.home[2]) * 1e3:+.3f} mm from its height, '
        f'{np.linalg.norm(end[:2] - quad.home[:2]) * 1e3:.2f} mm beside it, tilted '
        f'{np.degrees(tilt):.3f} deg; farthest {off.max() * 1e3:.1f} mm, tilt at most '
        f'{np.degrees(max(_tilt(o) for *_, o in run)):.2f} deg, failed cycles '
        f"{obs.diagnostics['qp_failures']}"
    )
    assert "task 'base': starting " in log and 'moved there along its trajectory' in log
    # a step of the target: 0.5 m past it
    assert off.max() < off[0] + 0.05  # the documented start's travel bound
    assert np.linalg.norm(end - quad.home) < GAP / 2
    assert tilt < level_tolerance(quad)
