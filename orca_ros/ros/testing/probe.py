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
A probe node in the calling process: the eyes and hands of tests, benchmarks and the main job.

It records joint states, odometry, commands and diagnostics of a private ROS domain, sends task
targets and states, calls services, and waits on conditions (never on fixed wall-clock times).
"""

from __future__ import annotations

import threading
import time

import numpy as np
import orca_ros as orca

from ..common import answered_ns


class Probe:
    """Rclpy node in the calling process, spinning in a thread; records states and commands."""

    ARM_JOINTS = [f'joint_{i}' for i in range(7)]

    def __init__(
        self, domain: int, controller_ns: str = '/orca_controller', joints=None, relay_from=None,
        relay_states_to=None,
    ):
        from geometry_msgs.msg import PoseStamped
        from orca_ros.ros.common import COMMAND_QOS
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64MultiArray

        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node('probe', context=self.context)
        self.ns = controller_ns
        self.lock = threading.Lock()
        self.joints = list(joints or self.ARM_JOINTS)
        self.states: list = []  # (stamp, q, v)
        self.spin_errors: list = []  # errors raised by callbacks (the spin goes on)
        self._latest_stamp = -1.0  # the newest state's stamp (the tests' own states have 0)
        self.odom: list = []  # (stamp, position, quaternion xyzw)
        self.commands: list = []
        self.efforts: list = []  # (stamp, torques the simulator applied in the step before stamp)
        # best effort, as sensor data, with a deep queue: a probe that falls behind for a moment
        # (its Python thread, a loaded machine) keeps the states (depth 5 lost the pair of steps
        # a one-cycle torque jump was in: test_ros_trajectory's counterfactual)
        sensor = QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.node.create_subscription(JointState, '/joint_states', self._on_state, sensor)
        from nav_msgs.msg import Odometry
        from trajectory_msgs.msg import MultiDOFJointTrajectoryPoint

        self.MultiDOFJointTrajectoryPoint = MultiDOFJointTrajectoryPoint
        self.node.create_subscription(Odometry, '/odom', self._on_odom, sensor)
        from diagnostic_msgs.msg import DiagnosticArray

        self.diagnostics: dict = {}
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diag, 10)
        self.node.create_subscription(
            Float64MultiArray,
            '/effort_controller/commands',
            lambda m: self._append(self.commands, np.array(m.data)),
            COMMAND_QOS,
        )
        self.pub_target = {}
        self.PoseStamped = PoseStamped
        self.JointState = JointState
        self.Float64MultiArray = Float64MultiArray
        # entities are created before the executor thread starts: creating them while another
        # thread spins the node can leave that thread waiting on a stale wait set
        self.pub_target['ee'] = self.node.create_publisher(
            PoseStamped, f'{controller_ns}/tasks/ee/target_pose', 10
        )
        self.pub_state = self.node.create_publisher(JointState, '/joint_states', 10)
        self.pub_command = self.node.create_publisher(
            Float64MultiArray, '/effort_controller/commands', COMMAND_QOS
        )
        # relay_from (a topic): the probe joins the lockstep loop. The controller sends its
        # commands there (its command_topic); the probe calls relay_hook(answered) (e.g. to send
        # the target of the next simulated instant), then forwards the command to the simulator,
        # so the loop advances only as fast as the probe keeps up. ``answered``: the instant [s]
        # of the state the command answers (the command names it, common.ANSWERS), None when it
        # names none. A state announced again is answered again with the same command: the
        # hook sees that instant twice (counting the relayed commands as steps ran the targets
        # ahead of the simulation by a step at each, and a ball posed ahead stepped the lwr's
        # torques)
        self.relay_hook = None
        self.relay_errors: list = []
        if relay_from:
            self.node.create_subscription(
                Float64MultiArray, relay_from, self._relay, COMMAND_QOS
            )
        # relay_states_to (a topic): the controller hears the simulator's joint states there
        # (its joint_states remapped), through the probe, while ``relay_states`` is True: a test
        # cuts the controller's state line while the simulator and its drives go on
        self.relay_states = True
        self.pub_relayed_states = None
        if relay_states_to:
            from orca_ros.ros.common import STATE_QOS

            self.pub_relayed_states = self.node.create_publisher(
                JointState, relay_states_to, STATE_QOS
            )
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._stop = False
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()
        self.robot = orca.RobotModel()
        self.robot.load_model_from_file(orca.default_urdf_path())

    @staticmethod
    def state_message(names, q, v):
        """Make a sensor_msgs/JointState with these names, positions and velocities (no stamp)."""
        from sensor_msgs.msg import JointState

        m = JointState()
        m.name = list(names)
        m.position = [float(x) for x in q]
        m.velocity = [float(x) for x in v]
        return m

    def _relay(self, m):
        hook = self.relay_hook
        if hook is not None:
            try:
                answered = answered_ns(m)
                hook(None if answered is None else answered * 1e-9)
            except Exception as exc:  # noqa: BLE001 - reported to the test, the loop goes on
                self.relay_errors.append(exc)
        self.pub_command.publish(m)

    def _spin(self):
        while not self._stop and self.context.ok():
            try:
                self.executor.spin_once(timeout_sec=0.05)
            except Exception as exc:  # noqa: BLE001 - a callback's error must not stop the
                # recording (the thread would die silently and every state after be missed)
                if len(self.spin_errors) < 100:
                    self.spin_errors.append(repr(exc))

    def _append(self, lst, item):
        with self.lock:
            lst.append(item)

    def _on_state(self, m):
        if self.pub_relayed_states is not None and self.relay_states:
            self.pub_relayed_states.publish(m)
        stamp = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
        q = dict(zip(m.name, m.position))
        if any(j not in q for j in self.joints):
            return  # the tests' own malformed states
        self._latest_stamp = max(self._latest_stamp, stamp)
        self._append(
            self.states, (stamp, np.array([q[j] for j in self.joints]), np.array(m.velocity))
        )
        if len(m.effort) == len(m.name):
            e = dict(zip(m.name, m.effort))
            self._append(self.efforts, (stamp, np.array([e[j] for j in self.joints])))

    def _on_odom(self, m):
        stamp = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
        p, o = m.pose.pose.position, m.pose.pose.orientation
        self._append(self.odom, (stamp, np.array([p.x, p.y, p.z]), np.array([o.x, o.y, o.z, o.w])))

    def _on_diag(self, m):
        for st in m.status:
            with self.lock:
                self.diagnostics = {kv.key: kv.value for kv in st.values}
                self.diagnostics['_message'] = st.message
                # the report's time on the node's clock (its publication)
                self.diagnostics['_stamp'] = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
                self.diagnostics['_level'] = (
                    int.from_bytes(st.level, 'little')
                    if isinstance(st.level, bytes)
                    else int(st.level)
                )

    def max_torque_step(self, t0: float, t1: float, dt: float = 1e-3) -> float:
        """
        Return the largest change of applied torque between consecutive simulation steps.

        Only pairs of states one step apart count (best-effort states may be dropped under load,
        and a difference across a gap is not a one-cycle step); at least one pair must exist.
        """
        with self.lock:
            eff = [e for e in self.efforts if t0 <= e[0] <= t1]
        steps = [
            np.abs(b[1] - a[1]).max()
            for a, b in zip(eff, eff[1:])
            if abs(b[0] - a[0] - dt) < 0.25 * dt
        ]
        if not steps:
            raise AssertionError(f'no consecutive simulation steps recorded in [{t0}, {t1}]')
        return float(max(steps))

    def last_state(self):
        with self.lock:
            return self.states[-1] if self.states else None

    def wait_for(self, predicate, timeout: float, what: str):
        t0 = time.time()
        while time.time() - t0 < timeout:
            if predicate():
                return
            time.sleep(0.02)
        raise AssertionError(f'timed out after {timeout} s waiting for {what}')

    def sim_time(self) -> float:
        """
        Return the simulated time: the newest stamp of a joint state (-1 before any).

        Not the last state's: a test's own unstamped states (bad input) come in between.
        """
        return self._latest_stamp

    def wait_sim(self, seconds: float, timeout: float = 60.0):
        t_end = self.sim_time() + seconds
        self.wait_for(lambda: self.sim_time() >= t_end, timeout, f'{seconds} s of simulated time')

    def ee_pose(self, q=None) -> np.ndarray:
        if q is None:
            # commands can arrive before the first state does (discovery order): wait for one
            self.wait_for(lambda: self.last_state() is not None, 30.0, 'a joint state')
            q = self.last_state()[1]
        self.robot.set_robot_state(q, np.zeros(7))
        return self.robot.get_frame_pose('link_7')

    def publish_until(
        self, publish, predicate, what: str, timeout: float = 60.0, period: float = 0.02
    ):
        """
        Call ``publish()`` every ``period`` s until ``predicate()`` holds.

        Discovery is asymmetric (a busy node may take seconds to accept messages from a publisher
        that already sees its subscription), so a message that must arrive is repeated until its
        effect shows, never sent once or for a fixed time.
        """
        t0 = time.time()
        while True:
            publish()
            t1 = time.time()
            while time.time() - t1 < period:
                if predicate():
                    return
                time.sleep(0.002)
            if time.time() - t0 > timeout:
                raise AssertionError(f'timed out after {timeout} s waiting for {what}')

    def moved_towards(self, T: np.ndarray, distance: float = 1e-3):
        """
        Predicate.

        The end effector has moved ``distance`` towards ``T``'s position since now.
        """
        p0 = self.ee_pose()[:3, 3].copy()
        d = T[:3, 3] - p0
        d = d / max(np.linalg.norm(d), 1e-12)
        return lambda: (self.ee_pose()[:3, 3] - p0) @ d > distance

    def send_target(
        self, task: str, T: np.ndarray, frame_id: str = '', until=None, timeout: float = 60.0
    ):
        """
        Publish a pose target.

        With ``until`` (a predicate), repeat it until the predicate holds (the same target again
        continues the same trajectory).
        """
        from orca_ros.ros.common import matrix_to_pose

        pub = self._target_publisher(task, task, self.PoseStamped, 'target_pose')
        msg = self.PoseStamped()
        msg.header.frame_id = frame_id
        matrix_to_pose(T, msg.pose)
        if until is None:
            pub.publish(msg)
        else:
            self.publish_until(
                lambda: pub.publish(msg), until, f"the effect of {task}'s target", timeout
            )

    def send_ee_offset(self, offset) -> np.ndarray:
        """
        Send task ``ee`` the end effector's pose moved by ``offset`` [m]; return that target.

        Repeated until the end effector moves towards it (:meth:`moved_towards`).
        """
        target = self.ee_pose()
        target[:3, 3] += offset
        self.send_target('ee', target, until=self.moved_towards(target))
        return target

    def _target_publisher(self, key: str, task: str, msg_type, topic: str):
        """Return publisher ``key`` on <ns>/tasks/<task>/<topic>, made once, once matched."""
        if key not in self.pub_target:
            self.pub_target[key] = self.node.create_publisher(
                msg_type, f'{self.ns}/tasks/{task}/{topic}', 10
            )
        pub = self.pub_target[key]
        # a message published before discovery matched the controller's subscription is lost
        self.wait_for(
            lambda: pub.get_subscription_count() > 0, 60.0, f"a subscriber on {task}'s {topic}"
        )
        return pub

    def send_target_point(self, task: str, position, velocity=(0, 0, 0), acceleration=(0, 0, 0)):
        """
        Cartesian target with feed-forward (orientation identity).

        In the controller's base frame.
        """
        from geometry_msgs.msg import Transform, Twist

        pub = self._target_publisher(
            f'{task}/point', task, self.MultiDOFJointTrajectoryPoint, 'target_point'
        )
        msg = self.MultiDOFJointTrajectoryPoint()
        tr = Transform()
        tr.translation.x, tr.translation.y, tr.translation.z = (float(v) for v in position)
        tr.rotation.w = 1.0
        msg.transforms = [tr]
        for vec, out in ((velocity, msg.velocities), (acceleration, msg.accelerations)):
            tw = Twist()
            tw.linear.x, tw.linear.y, tw.linear.z = (float(v) for v in vec)
            out.append(tw)
        pub.publish(msg)

    def call(self, srv_type, name: str, request, timeout: float = 10.0):
        cli = self.node.create_client(srv_type, name)
        if not cli.wait_for_service(timeout_sec=timeout):
            raise AssertionError(f'service {name} not available')
        fut = cli.call_async(request)
        self.wait_for(fut.done, timeout, f'answer of {name}')
        return fut.result()

    def unpause(self, timeout: float = 60.0, simulator: str = 'pybullet') -> None:
        """
        Let a bridge started with ``start_paused:=true`` go (its ``~/unpause`` service).

        ``simulator``: the bridge's (``pybullet``: ``/pybullet_bridge``, ``mujoco``: ...).
        """
        from std_srvs.srv import Trigger  # noqa: PLC0415

        res = self.call(Trigger, f'/{simulator}_bridge/unpause', Trigger.Request(),
                        timeout=timeout)
        if not res.success:
            raise AssertionError(f'the bridge refused to unpause: {res.message}')

    def close(self):
        self._stop = True
        self.thread.join(timeout=5)
        self.node.destroy_node()
        self.rclpy.shutdown(context=self.context)
