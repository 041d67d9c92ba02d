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
The documentation builds with warnings as errors: ``sphinx-build -W`` of docs/ into a tmp dir.

A broken cross-reference, a page missing from a toctree, a toctree entry without its page or a
docstring autodoc cannot read fails here, as it would on the ROS build farm (rosdoc2).
"""

import os
import re
import subprocess
import sys

from orca_ros.ros.parameter_schema import SCHEMA
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
pytest.importorskip('sphinx')
pytest.importorskip('myst_parser')


def test_sphinx_build_has_no_warning(tmp_path):
    out = tmp_path / 'html'
    run = subprocess.run(
        [sys.executable, '-m', 'sphinx', '-W', '--keep-going', '-E', '-q', '-b', 'html',
         '-d', str(tmp_path / 'doctrees'), os.path.join(ROOT, 'docs'), str(out)],
        capture_output=True, text=True, timeout=300,
        env={**os.environ, 'MPLBACKEND': 'Agg'},
    )
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    assert run.stderr.strip() == '', run.stderr[-4000:]
    # every source page became a page of the site
    for dirpath, _, files in os.walk(os.path.join(ROOT, 'docs')):
        if '_build' in dirpath or '_ext' in dirpath:
            continue
        for f in files:
            if f.endswith('.md'):
                rel = os.path.relpath(os.path.join(dirpath, f), os.path.join(ROOT, 'docs'))
                assert (out / rel.replace('.md', '.html')).is_file(), rel
    # the generated reference and the picture made it into the site
    html = (out / 'reference' / 'parameters.html').read_text()
    built = re.findall(r'<tr[^>]*><td><p><code[^>]*><span class="pre">([^<]+)</span>', html)
    assert [n.replace('&lt;', '<').replace('&gt;', '>') for n in built] == [s.name for s in SCHEMA]
    assert (out / '_images' / 'main_job_run.png').is_file()
