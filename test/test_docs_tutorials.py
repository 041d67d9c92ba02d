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
Every tutorial runs as written: the ```python blocks of each page, in order, in one namespace.

The pages are docs/getting_started.md and docs/tutorials/*.md. The claims of a page's text are
asserts in its blocks, so a tutorial whose numbers no longer hold fails here. Blocks run in a
temporary working directory (files they write land there).
"""

import glob
import os
import re

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGES = [os.path.join(ROOT, 'docs', 'getting_started.md')] + sorted(
    p for p in glob.glob(os.path.join(ROOT, 'docs', 'tutorials', '*.md'))
    if os.path.basename(p) != 'index.md'
)
# pages whose commands are checked elsewhere: the browser view needs a browser
# (test/test_ros_web_view.py drives headless Chromium through the page), two machines need two
# network stacks (test/test_ros_two_hosts.py runs the page's three commands in two namespaces)
CHECKED_ELSEWHERE = {
    'web_view.md': 'test_ros_web_view.py',
    'two_machines.md': 'test_ros_two_hosts.py',
}
BLOCK = re.compile(r'^```python\n(.*?)^```', re.S | re.M)


def python_blocks(path: str) -> list[tuple[int, str]]:
    """Return (line number, code) of each ```python block of a Markdown page."""
    with open(path) as fh:
        text = fh.read()
    return [(text.count('\n', 0, m.start()) + 2, m.group(1)) for m in BLOCK.finditer(text)]


def test_every_tutorial_has_code_to_run():
    assert len(PAGES) >= 12
    for page in PAGES:
        other = CHECKED_ELSEWHERE.get(os.path.basename(page))
        if other:
            assert os.path.isfile(os.path.join(ROOT, 'test', other)), other
            continue
        assert python_blocks(page), f'{page} has no ```python block'


@pytest.mark.parametrize('page', PAGES, ids=lambda p: os.path.relpath(p, ROOT))
def test_tutorial_runs_and_its_claims_hold(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv('MPLBACKEND', 'Agg')
    namespace = {'__name__': '__tutorial__'}
    for line, code in python_blocks(page):
        exec(compile(code, f'{page}:{line}', 'exec'), namespace)
