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
"""Helpers shared by the ROS 2 nodes (parameters, QoS, executors, message conversions)."""

from __future__ import annotations

import sys
import time

import numpy as np
import rclpy
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

STATE_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.BEST_EFFORT, history=HistoryPolicy.KEEP_LAST
)
# a command's reader (the hardware) applies the latest only: depth 1
COMMAND_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
)
# its writer keeps the last second at 1 kHz: a reliable reader that lags (a recorder on a busy
# machine) still receives every command. With depth 1 the writer replaced samples not yet
# acknowledged, and a recorded bag missed commands
COMMAND_WRITER_QOS = QoSProfile(
    depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
)
DEFAULT_QOS = QoSProfile(
    depth=10, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
)
# robot_state_publisher's convention: the URDF text, latched for late subscribers
DESCRIPTION_QOS = QoSProfile(
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    history=HistoryPolicy.KEEP_LAST,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)


def param(node, name, default):
    """Value of a parameter (declared from overrides, or declared here with its default)."""
    if node.has_parameter(name):
        value = node.get_parameter(name).value
        return default if value is None else value
    return node.declare_parameter(name, default).value


def nested_parameters(node, prefix: str) -> dict:
    """
    Return all parameters under ``prefix.`` as a nested dict.

    ``tasks.ee.kp`` -> {'ee': {'kp': ...}}.
    """
    out: dict = {}
    for name, p in node.get_parameters_by_prefix(prefix).items():
        value = p.value
        if isinstance(value, (list, tuple)) or type(value).__name__ == 'array':
            value = list(value)
        d = out
        keys = name.split('.')
        for k in keys[:-1]:
            d = d.setdefault(k, {})
        d[keys[-1]] = value
    return out


def wait_for_robot_description(node, timeout: float) -> str:
    """Take the URDF from the latched ``robot_description`` topic; wait up to ``timeout`` [s]."""
    from std_msgs.msg import String  # noqa: PLC0415

    got = []
    sub = node.create_subscription(
        String, 'robot_description', lambda m: got.append(m.data), DESCRIPTION_QOS
    )
    topic = node.resolve_topic_name('robot_description')
    node.get_logger().info(f'no urdf_path or robot_description parameter: waiting on {topic}')
    t0 = time.monotonic()
    while not got and rclpy.ok(context=node.context):
        if timeout > 0.0 and time.monotonic() - t0 > timeout:
            raise RuntimeError(
                'no URDF: no urdf_path or robot_description parameter, and nothing on '
                f'{topic} within {timeout:.0f} s (robot_description_timeout)'
            )
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_subscription(sub)
    if not got:
        raise RuntimeError('shut down while waiting for the URDF')
    node.get_logger().info(f'URDF from {topic} ({len(got[-1])} characters)')
    return got[-1]


def make_executor():
    """
    Make an EventsExecutor where this rclpy has it (lower overhead), else a single-threaded one.

    Drive it with repeated ``spin_once`` calls (as :func:`run_node` does): with rclpy 7.1.6 (PyPI),
    ``EventsExecutor.spin()`` never fires timers while ``spin_once`` does (measured).
    """
    try:
        from rclpy.experimental import EventsExecutor  # noqa: PLC0415

        return EventsExecutor()
    except Exception:  # pragma: no cover - depends on the installed rclpy
        return rclpy.executors.SingleThreadedExecutor()


def run_node(node_class, args=None, on_shutdown: str | None = None) -> int:
    """
    Console-script body.

    init, spin ``node_class()`` until SIGINT / SIGTERM / shutdown, then call its ``on_shutdown``
    method *while the context is still valid* (the controller publishes its hold command there),
    clean up and return an exit code.

    No traceback on a signal; a node that cannot start (bad parameters, missing URDF) says why in
    one line and returns 1.
    """
    import signal  # noqa: PLC0415

    from rclpy.signals import SignalHandlerOptions  # noqa: PLC0415

    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # noqa: BLE001 - malformed --ros-args: one line, no traceback
        print(f'{node_class.__name__}: cannot start: {exc}', file=sys.stderr)
        return 2
    received: list[int] = []

    def on_signal(signum, _frame):
        received.append(signum)

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    node = None
    code = 0
    try:
        node = node_class()
        # process-wide settings (scheduling) belong to the process that runs the node, not to a
        # node built inside another program: applied here, before the executor's threads start
        if hasattr(node, 'configure_process'):
            node.configure_process()
        executor = make_executor()
        executor.add_node(node)
        while not received and rclpy.ok() and node.context.ok():
            executor.spin_once(timeout_sec=0.05)
    except Exception as exc:  # noqa: BLE001 - start-up errors: one clear line, no traceback
        name = getattr(node_class, '__name__', 'node')
        print(f'[{name}] cannot run: {type(exc).__name__}: {exc}', flush=True)
        code = 1
    finally:
        if node is not None:
            if received:
                node.get_logger().info(
                    f'{signal.Signals(received[0]).name} received: shutting down'
                )
            if on_shutdown:
                try:
                    getattr(node, on_shutdown)()
                except Exception as exc:  # noqa: BLE001
                    node.get_logger().error(f'shutdown action failed: {exc}')
            node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
        for s, h in previous.items():
            signal.signal(s, h)
    return code


def stamp_to_sec(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


# lockstep: a command names the state it answers in its layout's label (its dimension, the
# joints: a consumer that reads only ``data``, as ros2_control's, is unaffected), so that the
# simulator steps once per instant even when the same answer comes twice
ANSWERS = 'answers_state_ns='


def answered_ns(msg) -> int | None:
    """Return the instant [ns] of the state a command names (:data:`ANSWERS`), or None."""
    for dim in msg.layout.dim:
        if dim.label.startswith(ANSWERS):
            try:
                return int(dim.label[len(ANSWERS):])
            except ValueError:
                return None
    return None


def stamp_ns(stamp) -> int:
    """Return a message stamp in integer nanoseconds (exact, to compare stamps)."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def sec_to_stamp(t: float, msg_stamp) -> None:
    sec = int(np.floor(t))
    msg_stamp.sec = sec
    msg_stamp.nanosec = int(round((t - sec) * 1e9)) % 1_000_000_000


def pose_to_matrix(pose) -> np.ndarray:
    """
    geometry_msgs/Pose -> 4x4.

    Raises ValueError on non-finite or zero quaternions.
    """
    p, o = pose.position, pose.orientation
    vals = np.array([p.x, p.y, p.z, o.x, o.y, o.z, o.w], dtype=float)
    if not np.all(np.isfinite(vals)):
        raise ValueError('pose contains NaN or infinite values')
    q = vals[3:]
    nq = np.linalg.norm(q)
    if nq < 1e-6:
        raise ValueError('pose orientation is a zero quaternion')
    x, y, z, w = q / nq
    T = np.eye(4)
    T[:3, :3] = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    T[:3, 3] = vals[:3]
    return T


def matrix_to_pose(T: np.ndarray, pose) -> None:
    from ..math.rotations import quaternion_xyzw  # noqa: PLC0415

    x, y, z, w = (float(c) for c in quaternion_xyzw(T[:3, :3]))
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in T[:3, 3])
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
