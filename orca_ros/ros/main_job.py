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
The main job: the arm driven through ROS 2 exactly as a user would drive a robot.

Starts a simulator's bridge (``pybullet_bridge``, or ``mujoco_bridge`` with ``--sim mujoco``) and
``orca_controller`` as separate processes (launch-free, private ROS domain), sends a sequence of
Cartesian targets on ``~/tasks/ee/target_pose``, runs one ``~/deactivate`` / ``~/activate``
cycle, then prints a report (tracking error and settle time per
target, solve time, limit margins, what saturated). The run is recorded in a rosbag2 file (MCAP:
joint states, commands, targets, task error, solve time per cycle, diagnostics, the URDF) by
``bag_recorder`` (each target is sent until the arm moves and the recorder has it), and drawn from
that file by the ``plot`` command's code. Lockstep simulation by
default (deterministic, faster than real time); ``--realtime`` runs the bridge at wall-clock rate
with the controller on its timer; ``--gui`` shows the simulator's window; ``--web`` starts
``web_view`` (the robot and its targets in the browser during the run; the URL printed,
``--web-port`` its port). ``--stay``: after the report the nodes (and the page) keep running until
Ctrl-C, for a newcomer to drag the target and watch the arm follow.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time

import numpy as np

from .testing.launch_free import free_domain_id, Procs
from .testing.probe import Probe

TARGET_TOPIC = '/orca_controller/tasks/ee/target_pose'
OFFSETS = [
    np.array(o)
    for o in ([0.10, 0.0, 0.0], [0.10, -0.15, 0.05], [0.0, -0.15, -0.10], [0.0, 0.0, 0.0])
]


def _wait_reached(probe, target, tol, timeout_sim):
    """
    Return the simulated time until the end effector stays within tol of target.

    NaN if never.
    """
    t_start = probe.sim_time()
    t_in = None
    while probe.sim_time() - t_start < timeout_sim:
        err = np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3])
        if err < tol:
            t_in = probe.sim_time() if t_in is None else t_in
            if probe.sim_time() - t_in > 0.2:
                return t_in - t_start
        else:
            t_in = None
        time.sleep(0.01)
    return float('nan')


def _in_bag(procs, T):
    """
    Return a predicate: the recorder has the target message the probe sends for pose ``T``.

    The message is built as ``Probe.send_target`` builds it (no stamp, base frame); the recorder
    logs a receipt for each distinct message on the target topic.
    """
    from geometry_msgs.msg import PoseStamped  # noqa: PLC0415

    from .bag_recorder import receipt  # noqa: PLC0415
    from .common import matrix_to_pose  # noqa: PLC0415

    msg = PoseStamped()
    msg.header.frame_id = ''
    matrix_to_pose(T, msg.pose)
    line = receipt(TARGET_TOPIC, msg)
    return lambda: line in procs.log('recorder')


def _launch_robot(procs, args, mode: str) -> None:
    """Start the simulated arm (paused until the recorder hears it) and its controller."""
    if args.attach:
        return
    procs.start_arm(
        mode,
        simulator=args.sim,
        bridge_args=(
            '-p',
            f"gui:={'true' if args.gui else 'false'}",
            '-p',
            'start_paused:=true',  # until the recorder hears both sides
        ),
    )


def _start_web_view(procs, port: int):
    """Start ``web_view`` beside the run; return its URL, or None (its one line printed)."""
    p = procs.start('orca_ros.ros.web_view', '-p', f'port:={port}', name='web_view')
    t0 = time.time()
    while time.time() - t0 < 60:
        log = procs.log('web_view')
        if 'web view: http' in log:
            return log.split('web view: ')[1].split()[0]
        if p.poll() is not None:
            print(f"--web: {(log.strip().splitlines() or ['web_view exited'])[-1]}")
            return None
        time.sleep(0.05)
    print('--web: web_view did not start within 60 s')
    return None


def _stay(url) -> None:
    """Keep the nodes running until Ctrl-C (``--stay``): the user drives the arm now."""
    where = f' ({url}: drag the target)' if url else ''
    # Ctrl-C ends them even when the job was started with SIGINT ignored (inherited from its
    # parent: Python then installs no handler; a test suite's process had, and the job stayed)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    print(f'the arm and its controller keep running{where}; Ctrl-C ends them', flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:  # a terminal's Ctrl-C reaches the nodes too; a second one waits
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        print('stopping the nodes', flush=True)


def _report(args, probe, rows, diag, states, sim_rate, bag, logs, t_wall0) -> bool:
    """
    Print the run's report (the targets' table, solve times, the bag's summary); draw its plots.

    True if every target was reached.
    """
    ok = True
    robot = probe.robot
    q = np.array([s[1] for s in states])
    t = np.array([s[0] for s in states])
    path = np.array([probe.ee_pose(qi)[:3, 3] for qi in q[::20]])
    print(
        f'=== orca_ros main job: 7-DoF arm through ROS 2 ({args.sim}_bridge + orca_controller, '
        f"{'real time' if args.realtime else 'lockstep'}) ==="
    )
    print(f"{'step':<28}{'target [m]':<28}{'final error':>13}{'settle time':>13}")
    for name, p, err, settle in rows:
        reached = err < args.tolerance
        ok &= reached
        where = ' '.join(f'{round(x, 3) + 0.0:+.3f}' for x in p)  # no '-0.000'
        print(
            f'{name:<28}{where:<28}{err * 1e3:>10.3f} mm{settle:>11.2f} s'
            f"{'' if reached else '   NOT REACHED'}"
        )
    print(
        f"solve time: median {diag.get('solve_time_median_us', '?')} us, p99 "
        f"{diag.get('solve_time_p99_us', '?')} us"
        f" ({diag.get('solver', '?')}); solver status {diag.get('solver_status', '?')}"
    )
    if args.realtime:
        print(
            f"control loop: mean period {diag.get('loop_period_mean_ms', '?')} ms "
            f"(nominal 1 ms), p99 {diag.get('loop_period_p99_ms', '?')} ms"
        )
    else:
        print(
            f'lockstep: one control cycle per 1 ms simulation step; simulated time ran at '
            f'{sim_rate:.2f}x wall-clock time'
        )
    from ..recording import read_run  # noqa: PLC0415
    from ..recording.run_plots import plot_run  # noqa: PLC0415
    from ..recording.run_report import report  # noqa: PLC0415

    run = read_run(bag)
    for line in report(run)[1:]:
        print(line)
    print(f"recorded: {bag} ({', '.join(f'{k} {n}' for k, n in sorted(run.counts.items()))})")
    print(f'node logs: {logs}')
    p1 = plot_run(run, os.path.join(args.output_dir, 'main_job_run.png'))
    import matplotlib.pyplot as plt  # noqa: PLC0415 (plot_run chose the backend)

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    tg = np.array([r[1] for r in rows])
    axes[0].plot(path[:, 0], path[:, 1], lw=1, label='end effector')
    axes[0].plot(tg[:, 0], tg[:, 1], 'rx', ms=9, label='targets')
    axes[0].set_xlabel('x [m]')
    axes[0].set_ylabel('y [m]')
    axes[0].axis('equal')
    axes[0].legend()
    axes[1].plot(t[::20] - t[0], path[:, 2], lw=1)
    axes[1].set_xlabel('time [s]')
    axes[1].set_ylabel('z [m]')
    for ax in axes:
        ax.grid(True)
    fig.suptitle(f'end-effector path, {robot.name}, {len(rows) - 1} targets', fontsize=10)
    fig.tight_layout()
    p2 = os.path.join(args.output_dir, 'main_job_path.png')
    fig.savefig(p2, dpi=100)
    plt.close(fig)
    print(f'plots: {p1}, {p2}  (any bag: plot <bag>)')
    print(f'wall time {time.time() - t_wall0:.1f} s')
    print('RESULT:', 'every target reached' if ok else 'FAILED')
    return ok


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        '--realtime', action='store_true', help='free-running bridge at wall-clock rate'
    )
    ap.add_argument('--sim', choices=('pybullet', 'mujoco'), default='pybullet',
                    help='the simulator standing in for the arm [pybullet]')
    ap.add_argument('--gui', action='store_true', help="show the simulator's window")
    ap.add_argument('--stay', action='store_true',
                    help='after the report, keep the nodes (and the page) running until Ctrl-C')
    ap.add_argument(
        '--web', action='store_true', help='the robot and its targets in the browser (web_view)'
    )
    ap.add_argument('--web-port', type=int, default=8080, help="web_view's port [8080]")
    ap.add_argument('--output-dir', default='output')
    ap.add_argument('--bag', help='rosbag2 directory to write [<output-dir>/run_<date-time>]')
    ap.add_argument(
        '--tolerance', type=float, default=1e-3, help='reached when within this distance [m]'
    )
    ap.add_argument(
        '--attach',
        action='store_true',
        help='start no bridge or controller: drive the ones already running on ROS_DOMAIN_ID '
        '(other machines included); the recorder runs here',
    )
    args = ap.parse_args(argv)
    t_wall0 = time.time()
    if args.attach:  # the user's domain and discovery range (e.g. SUBNET across machines)
        domain = int(os.environ.get('ROS_DOMAIN_ID', '0'))
    else:
        domain = free_domain_id()
    os.makedirs(args.output_dir, exist_ok=True)
    bag = args.bag or os.path.join(args.output_dir, time.strftime('run_%Y%m%d-%H%M%S'))
    logs = f'{bag.rstrip(os.sep)}.logs'  # the nodes' output, next to the run's bag
    os.makedirs(logs, exist_ok=True)
    procs = Procs(domain, logs, local_only=not args.attach)
    mode = 'free_running' if args.realtime else 'lockstep'
    procs.start(
        'orca_ros.ros.bag_recorder',
        '-p', f'output:={bag}',
        '-p', f"use_sim_time:={'false' if args.realtime else 'true'}",
        '-p', f"confirm_topics:=['{TARGET_TOPIC}']",  # receipts of the targets (see _in_bag)
        name='recorder',
    )
    procs.wait_log('recorder', 'recording', timeout=60)
    _launch_robot(procs, args, mode)
    url = None
    if args.web:
        url = _start_web_view(procs, args.web_port)
        if url:
            print(f'web view: {url} (open it in a browser to watch the run)', flush=True)
    probe = Probe(domain)
    rows = []
    failed = True  # until the run is over (a failed or interrupted run stops every node)
    waiting = {}  # the predicates a target waits for (printed if it times out)
    try:
        # discovery is asynchronous: the run starts once the recorder receives states and
        # commands, so the bag holds it from its first step
        procs.wait_recorded('recorder')
        if not args.attach:
            probe.unpause(simulator=args.sim)
        from std_srvs.srv import Trigger  # noqa: PLC0415

        probe.wait_for(lambda: probe.sim_time() >= 0.0, 60, 'joint states of the arm')
        t_start = probe.sim_time()
        probe.wait_for(
            lambda: probe.sim_time() > t_start + 1.0,
            60,
            'the controller driving the simulated arm',
        )
        start = probe.ee_pose()
        sim0, wall0 = probe.sim_time(), time.time()
        targets = []
        for k, off in enumerate(OFFSETS):
            T = start.copy()
            T[:3, 3] += off
            targets.append(T)
            # repeated until the arm moves and the bag has it: discovery may drop a new
            # publisher's first messages, on each subscriber separately (under load the recorder
            # once matched the target publisher after the controller did and lost a target)
            moved, in_bag = probe.moved_towards(T), _in_bag(procs, T)
            waiting = {'the arm moved towards it': moved, 'the recorder has it': in_bag}
            probe.send_target('ee', T, until=lambda: moved() and in_bag())
            settle = _wait_reached(probe, T, args.tolerance, 6.0)
            err = np.linalg.norm(probe.ee_pose()[:3, 3] - T[:3, 3])
            rows.append((f'target {k + 1}', T[:3, 3], err, settle))
        # one deactivate / activate cycle: everything ramps out (the arm holds with gravity), then
        # back in
        probe.call(Trigger, '/orca_controller/deactivate', Trigger.Request())
        probe.wait_sim(1.5)
        probe.call(Trigger, '/orca_controller/activate', Trigger.Request())
        settle = _wait_reached(probe, targets[-1], args.tolerance, 6.0)
        err = np.linalg.norm(probe.ee_pose()[:3, 3] - targets[-1][:3, 3])
        rows.append(('after deactivate/activate', targets[-1][:3, 3], err, settle))
        sim_rate = (probe.sim_time() - sim0) / (time.time() - wall0)
        time.sleep(0.5)  # one more diagnostics message
        diag = dict(probe.diagnostics)
        with probe.lock:
            states = list(probe.states)
        failed = False
    except AssertionError as exc:
        print(f'main job failed: {exc}')
        with probe.lock:
            n_states = len(probe.states)
            last = probe.states[-1][0] if probe.states else None
        print(f'the job saw {n_states} joint states, the last stamped {last}, the newest '
              f'{probe.sim_time()}; end effector there {probe.ee_pose()[:3, 3]}; errors in '
              f'its callbacks: {probe.spin_errors[:3]}; '
              + ', '.join(f'{what}: {bool(p())}' for what, p in waiting.items()))
        if not args.attach:  # attached, the nodes' logs are the user's
            print(procs.log('controller')[-2000:])
        print(f'node logs: {logs}')
        return 1
    finally:
        probe.close()
        # the recorder closes the bag on SIGTERM (the report reads it); staying, the rest runs on
        procs.stop(*(('recorder',) if args.stay and not failed else ()))

    try:
        ok = _report(args, probe, rows, diag, states, sim_rate, bag, logs, t_wall0)
        if args.stay:
            _stay(url)
    finally:
        procs.stop()  # those still running (staying)
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
