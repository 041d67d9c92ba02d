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
The main job (the demo) end to end.

In its own module: the lockstep pair of test_ros_nodes' module fixture runs flat out until that
module ends, and would slow this run down on a 2-core machine.
"""


def test_main_job_reaches_every_target(tmp_path):
    import os
    import subprocess
    import sys

    # the timeout is a failsafe (a busy machine may take minutes), not a speed claim
    proc = subprocess.run(
        [sys.executable, '-m', 'orca_ros.ros.main_job', '--output-dir', str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=900,
        env=dict(os.environ, MPLBACKEND='Agg'),
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert 'RESULT: every target reached' in proc.stdout
    assert proc.stdout.count(' mm ') >= 5 and 'NOT REACHED' not in proc.stdout
    assert (tmp_path / 'main_job_torques.png').stat().st_size > 10_000
    assert (tmp_path / 'main_job_path.png').stat().st_size > 10_000
