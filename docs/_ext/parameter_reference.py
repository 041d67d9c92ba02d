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
The controller node's parameter reference, generated from ``orca_ros.ros.parameter_schema``.

A Sphinx extension: the page ``reference/parameters`` is built from ``render()``, whatever its
file holds, so the site always shows the schema. The committed file carries the same text for
readers of the repository: ``python docs/_ext/parameter_reference.py`` rewrites it, and
``test/test_docs_reference.py`` fails while it is out of date or while the table disagrees with
the schema.
"""

import importlib.util
import os
import sys

DOCS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGE = os.path.join(DOCS, 'reference', 'parameters.md')
SCHEMA_FILE = os.path.join(DOCS, '..', 'orca_ros', 'ros', 'parameter_schema.py')


def _schema_module():
    """
    Load parameter_schema.py by its path.

    It needs the standard library only, whereas importing it through the package would import
    the whole core (numpy, Pinocchio...), which a documentation build (rosdoc2's) may lack.
    """
    spec = importlib.util.spec_from_file_location('_orca_parameter_schema', SCHEMA_FILE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module

HEADER = """# Controller parameters

<!-- generated from orca_ros/ros/parameter_schema.py by docs/_ext/parameter_reference.py at every
docs build: edit the schema, not this page -->

Every parameter `orca_controller` accepts, as `orca_ros/ros/parameter_schema.py` declares it.
*live* parameters change at run time with `ros2 param set` (a request is applied whole or refused
whole, with the reason in the reply); *read-only* ones are fixed once the node runs. `<task>` and
`<constraint>` stand for the names listed under `tasks.names` and `constraints.names`. The same
table prints with `python -m orca_ros.ros.parameter_schema`.

"""


def render() -> str:
    """Return the page's Markdown text."""
    return HEADER + _schema_module().markdown() + '\n'


def write_if_changed(path: str = PAGE) -> bool:
    """Write the page; return True when its text changed."""
    text = render()
    if os.path.isfile(path):
        with open(path) as fh:
            if fh.read() == text:
                return False
    with open(path, 'w') as fh:
        fh.write(text)
    return True


DOCNAME = 'reference/parameters'


def _source_read(app, docname: str, source: list) -> None:
    if docname == DOCNAME:
        source[0] = render()


def setup(app):
    """Register the generator with Sphinx."""
    app.connect('source-read', _source_read)
    return {'version': '1', 'parallel_read_safe': True, 'parallel_write_safe': True}


if __name__ == '__main__':
    sys.stdout.write(f"{PAGE}: {'rewritten' if write_if_changed() else 'up to date'}\n")
