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
"""The README's command blocks, as the tests that run them read them."""

import os
import re
import shlex

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def code_block_after(heading: str) -> str:
    """Return the first fenced code block after the README line that starts with ``heading``."""
    with open(os.path.join(ROOT, 'README.md')) as fh:
        text = fh.read()
    start = text.index('\n' + heading)
    m = re.search(r'```[a-z]*\n(.*?)```', text[start:], re.S)
    assert m, f'no code block after {heading!r} in README.md'
    return m.group(1)


def ros_route() -> dict:
    """
    Return the README's ROS 2 route by tool: ``{'rosdep': argv, 'pip': argv, ...}``.

    Each line of the block is split at ``&&``; the first word of each part names it.
    """
    steps = {}
    for line in code_block_after('### The ROS 2 route').splitlines():
        for part in line.split('&&'):
            argv = shlex.split(part.strip())
            if argv:
                steps.setdefault(argv[0], argv)
    return steps
