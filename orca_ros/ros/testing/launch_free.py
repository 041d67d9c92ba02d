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
Launch-free multi-process runs.

The bridge and the controller as separate processes on a private ROS domain (the probe node that
watches and drives them from the calling process is :mod:`orca_ros.ros.testing.probe`).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import orca_ros as orca

_NEXT_DOMAIN = [100 + (os.getpid() * 7) % 60]
_FIRST_DOMAIN, _DOMAINS = 100, 130
_KEEP = 8  # domains a process holds at most: its latest runs'
_HELD: dict = {}  # domain -> the open lock file that holds it for this process, oldest first


def _claim(domain: int) -> bool:
    """Hold ``domain`` for this process (a lock on its file); False: another process holds it."""
    import fcntl  # noqa: PLC0415
    import tempfile  # noqa: PLC0415

    folder = os.path.join(tempfile.gettempdir(), 'orca_ros_domains')
    os.makedirs(folder, exist_ok=True)
    fh = open(os.path.join(folder, f'{domain}.lock'), 'w')
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        return False
    _HELD[domain] = fh  # released when the process ends, or when it has claimed _KEEP since
    while len(_HELD) > _KEEP:
        _HELD.pop(next(iter(_HELD))).close()  # its oldest run is over: the domain is free again
    return True


def free_domain_id(timeout: float = 60.0) -> int:
    """
    Return a ROS domain that no other run on this machine uses, nor this process lately.

    Domains 100..229, localhost-only discovery. Each is held by a lock file while the process
    lives, so two sessions (two test runs, two main jobs) never share one: they would hear each
    other's nodes (forced onto one, two runs of test_ros_obstacles.py both failed). A process
    holds its latest ``_KEEP`` domains only (a test session runs one after another): the others
    it used are free again. When every domain is held: this process's oldest is used again (its
    runs are over), or, holding none, it waits up to ``timeout`` seconds for one to be released,
    then raises RuntimeError saying so.
    """
    deadline = time.monotonic() + timeout
    while True:
        for _ in range(_DOMAINS):
            d = _NEXT_DOMAIN[0]
            _NEXT_DOMAIN[0] = _FIRST_DOMAIN + (d - _FIRST_DOMAIN + 1) % _DOMAINS
            if d not in _HELD and _claim(d):
                return d
        if _HELD:
            d = next(iter(_HELD))  # all taken: this process's oldest, moved to the end
            _HELD[d] = _HELD.pop(d)
            return d
        if time.monotonic() > deadline:
            raise RuntimeError(
                f'every ROS domain {_FIRST_DOMAIN}-{_FIRST_DOMAIN + _DOMAINS - 1} is held by '
                'other runs on this machine (lock files in the temporary folder, '
                'orca_ros_domains)'
            )
        time.sleep(0.5)


def ros_env(domain: int, local_only: bool = True) -> dict:
    """Environment of a launched node: its domain, and discovery on this machine only."""
    env = dict(os.environ)
    env.update(ROS_DOMAIN_ID=str(domain), PYTHONUNBUFFERED='1')
    if local_only:
        env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    return env


def _die_with_parent():
    """In the child before exec: SIGTERM when the parent dies (Linux), even by SIGKILL."""
    try:
        import ctypes  # noqa: PLC0415
        import signal  # noqa: PLC0415

        ctypes.CDLL('libc.so.6', use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


# what a recorder must hear before a recorded run starts (see Procs.wait_recorded)
RUN_TOPICS = ('/joint_states', '/effort_controller/commands')

# the shipped arm's start: bent (q = 0 is the stretched, singular posture)
ARM_Q0 = [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]


class Procs:
    def __init__(self, domain: int, tmp_path, local_only: bool = True):
        self.domain, self.tmp, self.procs = domain, tmp_path, []
        self.local_only = local_only

    def start(self, module: str, *ros_args: str, name: str, prefix=(), env=None):
        """
        Start ``python -m module --ros-args ...``, its output in ``<name>.log``.

        ``prefix``: a command the process runs under (e.g. ``ip netns exec <ns>``); ``env``:
        variables added to the node's environment.
        """
        log = open(os.path.join(self.tmp, f'{name}.log'), 'w')
        p = subprocess.Popen(
            [*prefix, sys.executable, '-m', module, '--ros-args', *ros_args],
            env={**ros_env(self.domain, self.local_only), **(env or {})},
            stdout=log,
            stderr=subprocess.STDOUT,
            # a killed parent (a test's timeout, Ctrl-C) leaves no node running on its domain
            preexec_fn=_die_with_parent,
        )
        self.procs.append((p, log, name))
        return p

    def start_arm_bridge(self, mode: str = 'lockstep', *ros_args: str, prefix=(), env=None,
                         simulator: str = 'pybullet'):
        """Start the shipped 7-DoF arm's simulator (``lwr.urdf``) at :data:`ARM_Q0`."""
        return self.start(
            f'orca_ros.ros.{simulator}_bridge',
            '-p',
            f'mode:={mode}',
            '-p',
            f'initial_positions:={ARM_Q0}',
            *ros_args,
            name='bridge',
            prefix=prefix,
            env=env,
        )

    def start_arm_controller(
        self, mode: str = 'lockstep', *ros_args: str, prefix=(), env=None, name='controller'
    ):
        """
        Start the controller with ``config/lwr_controller.yaml``.

        One cycle per joint state in lockstep, its timer otherwise; ``name``: its log's name.
        """
        return self.start(
            'orca_ros.ros.controller_node',
            '--params-file',
            orca.share_path('config', 'lwr_controller.yaml'),
            '-p',
            f"trigger:={'joint_state' if mode == 'lockstep' else 'timer'}",
            *ros_args,
            name=name,
            prefix=prefix,
            env=env,
        )

    def start_arm(self, mode: str = 'lockstep', controller_args=(), bridge_args=(),
                  simulator: str = 'pybullet'):
        """Start the arm's simulator (``simulator``'s bridge) and its controller."""
        self.start_arm_bridge(mode, *bridge_args, simulator=simulator)
        self.start_arm_controller(mode, *controller_args)

    def log(self, name: str) -> str:
        with open(os.path.join(self.tmp, f'{name}.log')) as fh:
            return fh.read()

    def assert_refused(self, proc, name: str, said: str, timeout: float = 120.0) -> None:
        """Assert that ``proc`` (logging as ``name``) exits 1 saying ``said``, no traceback."""
        assert proc.wait(timeout=timeout) == 1
        log = self.log(name)
        assert said in log, log
        assert 'Traceback' not in log, log

    def wait_log(self, name: str, text: str, timeout: float = 30.0) -> None:
        """Wait until ``name``'s log holds ``text`` (a condition, not a duration)."""
        t0 = time.time()
        while time.time() - t0 < timeout:
            if text in self.log(name):
                return
            time.sleep(0.05)
        raise AssertionError(
            f"no log line containing '{text}' from {name}:\n{self.log(name)[-3000:]}"
        )

    def wait_recorded(
        self, recorder: str = 'recorder', topics=RUN_TOPICS, timeout: float = 120.0
    ) -> None:
        """
        Wait until the recorder named ``recorder`` has received a first message on each topic.

        Discovery is asynchronous: a recorder that matches the simulator and the controller late
        misses the start of the run (a lockstep simulation, faster than real time, may be over
        before it hears it). Start the bridge with ``start_paused:=true``, wait for this, then
        unpause it (:meth:`orca_ros.ros.testing.probe.Probe.unpause`): the bag holds the run from
        its first step.
        """
        for topic in topics:
            self.wait_log(recorder, f'first message on {topic}', timeout=timeout)

    def stop(self, *names: str):
        """Stop the processes ``names`` (all if none): SIGTERM, SIGKILL after 10 s."""
        chosen = [e for e in self.procs if not names or e[2] in names]
        for p, log, _ in chosen:
            if p.poll() is None:
                p.terminate()
        for p, log, _ in chosen:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
            log.close()
