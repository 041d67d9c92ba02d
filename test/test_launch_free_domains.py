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
The private ROS domains of launch-free runs: a process holds a few, a full machine is said.

Two test sessions side by side once held every domain between them (a session kept each domain
it ever used), and a main job started then crashed on StopIteration. Each process now holds its
latest ``_KEEP`` domains only, and one that finds every domain held by others waits for one,
then says so.
"""

import os
import subprocess
import sys
import tempfile

import pytest

pytest.importorskip('fcntl')
from orca_ros.ros.testing import launch_free as lf  # noqa: E402,I100

HOLD_ALL = """
import fcntl, os, sys
folder = os.path.join(sys.argv[1], 'orca_ros_domains')
os.makedirs(folder, exist_ok=True)
held = {}
for d in range(100, 230):
    fh = open(os.path.join(folder, f'{d}.lock'), 'w')
    fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    held[d] = fh
print('held', flush=True)
for line in sys.stdin:  # a domain to release, one per line
    held.pop(int(line)).close()
    print('released', flush=True)
"""


@pytest.fixture
def private_locks(tmp_path, monkeypatch):
    """Keep the lock files in a folder of this test's own, this process holding none."""
    monkeypatch.setattr(tempfile, 'tempdir', str(tmp_path))
    monkeypatch.setattr(lf, '_HELD', {})
    return tmp_path


def test_a_process_holds_its_latest_domains_only(private_locks):
    got = [lf.free_domain_id() for _ in range(3 * lf._KEEP)]
    assert len(set(got)) == len(got)  # a new one each run (none of this process's lately)
    assert list(lf._HELD) == got[-lf._KEEP:]
    # the ones it let go are free for another process
    probe = subprocess.run(
        [sys.executable, '-c', 'import fcntl, sys; fh = open(sys.argv[1], "w"); '
         'fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)',
         os.path.join(str(private_locks), 'orca_ros_domains', f'{got[0]}.lock')],
        capture_output=True, text=True, timeout=60,
    )
    assert probe.returncode == 0, probe.stderr


def test_every_domain_held_elsewhere_waits_then_says_so(private_locks):
    child = subprocess.Popen([sys.executable, '-c', HOLD_ALL, str(private_locks)],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == 'held'
        with pytest.raises(RuntimeError, match='every ROS domain 100-229 is held'):
            lf.free_domain_id(timeout=1.0)
        child.stdin.write('150\n')
        child.stdin.flush()
        assert child.stdout.readline().strip() == 'released'
        assert lf.free_domain_id(timeout=30.0) == 150
    finally:
        child.kill()
        child.wait()
