"""Helpers shared by the ROS 2 nodes (parameters, QoS, executors, message conversions)."""
from __future__ import annotations

import numpy as np
import rclpy
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

STATE_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT, history=HistoryPolicy.KEEP_LAST)
COMMAND_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
DEFAULT_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)


def param(node, name, default):
    """Value of a parameter (declared from overrides, or declared here with its default)."""
    if node.has_parameter(name):
        value = node.get_parameter(name).value
        return default if value is None else value
    return node.declare_parameter(name, default).value


def nested_parameters(node, prefix: str) -> dict:
    """All parameters under ``prefix.`` as a nested dict (``tasks.ee.kp`` -> {'ee': {'kp': ...}})."""
    out: dict = {}
    for name, p in node.get_parameters_by_prefix(prefix).items():
        value = p.value
        if isinstance(value, (list, tuple)) or type(value).__name__ == "array":
            value = list(value)
        d = out
        keys = name.split(".")
        for k in keys[:-1]:
            d = d.setdefault(k, {})
        d[keys[-1]] = value
    return out


def make_executor():
    """EventsExecutor where this rclpy has it (lower overhead), else the single-threaded one.

    Drive it with :func:`spin`: with rclpy 7.1.6 (PyPI), ``EventsExecutor.spin()`` never fires timers while
    repeated ``spin_once`` calls do (measured), so both executors are driven the same way.
    """
    try:
        from rclpy.experimental import EventsExecutor  # noqa: PLC0415

        return EventsExecutor()
    except Exception:  # pragma: no cover - depends on the installed rclpy
        return rclpy.executors.SingleThreadedExecutor()


def spin(executor, node) -> None:
    """Run until shutdown (see :func:`make_executor`)."""
    while rclpy.ok() and node.context.ok():
        executor.spin_once(timeout_sec=0.1)


def run_node(node_class, args=None, on_shutdown: str | None = None) -> int:
    """Console-script body: init, spin ``node_class()`` until Ctrl-C / shutdown, call its ``on_shutdown``
    method (best effort), clean up."""
    rclpy.init(args=args)
    node = None
    try:
        node = node_class()
        executor = make_executor()
        executor.add_node(node)
        spin(executor, node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        if node is not None:
            if on_shutdown:
                try:
                    getattr(node, on_shutdown)()
                except Exception:
                    pass
            node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 0


def stamp_to_sec(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def sec_to_stamp(t: float, msg_stamp) -> None:
    sec = int(np.floor(t))
    msg_stamp.sec = sec
    msg_stamp.nanosec = int(round((t - sec) * 1e9)) % 1_000_000_000


def pose_to_matrix(pose) -> np.ndarray:
    """geometry_msgs/Pose -> 4x4. Raises ValueError on non-finite or zero quaternions."""
    p, o = pose.position, pose.orientation
    vals = np.array([p.x, p.y, p.z, o.x, o.y, o.z, o.w], dtype=float)
    if not np.all(np.isfinite(vals)):
        raise ValueError("pose contains NaN or infinite values")
    q = vals[3:]
    nq = np.linalg.norm(q)
    if nq < 1e-6:
        raise ValueError("pose orientation is a zero quaternion")
    x, y, z, w = q / nq
    T = np.eye(4)
    T[:3, :3] = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    T[:3, 3] = vals[:3]
    return T


def matrix_to_pose(T: np.ndarray, pose) -> None:
    from ..math.rotations import quaternion_xyzw  # noqa: PLC0415

    x, y, z, w = (float(c) for c in quaternion_xyzw(T[:3, :3]))
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in T[:3, 3])
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
