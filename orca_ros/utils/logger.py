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
Project logger with levels settable from the command line.

``Logger.parse_argv(argv)`` understands ``-l LEVEL`` / ``--log_level LEVEL`` where LEVEL is one of
debug, info, warning, error (as the C++ library's examples accept), and returns the remaining
arguments.
"""

from __future__ import annotations

import logging
import sys

_LEVELS = {
    'debug': logging.DEBUG,
    'info': logging.INFO,
    'warning': logging.WARNING,
    'warn': logging.WARNING,
    'error': logging.ERROR,
}

_ROOT_NAME = 'orca_ros'


def get_logger(name: str | None = None) -> logging.Logger:
    """Child logger of the project's root logger (``orca_ros.<name>``)."""
    Logger._ensure_handler()
    return logging.getLogger(_ROOT_NAME if not name else f'{_ROOT_NAME}.{name}')


class Logger:
    """Static helpers around the ``orca_ros`` logging hierarchy."""

    _configured = False

    @classmethod
    def _ensure_handler(cls) -> None:
        if cls._configured:
            return
        root = logging.getLogger(_ROOT_NAME)
        if not root.handlers:
            handler = logging.StreamHandler(sys.stderr)
            handler.setFormatter(logging.Formatter('[%(levelname)s] [%(name)s] %(message)s'))
            root.addHandler(handler)
        if root.level == logging.NOTSET:
            root.setLevel(logging.INFO)
        root.propagate = False
        cls._configured = True

    @classmethod
    def set_level(cls, level: str | int) -> None:
        cls._ensure_handler()
        if isinstance(level, str):
            key = level.strip().lower()
            if key not in _LEVELS:
                raise ValueError(
                    f"unknown log level '{level}' (expected one of debug, info, warning, error)"
                )
            level = _LEVELS[key]
        logging.getLogger(_ROOT_NAME).setLevel(level)

    @classmethod
    def get_level(cls) -> int:
        cls._ensure_handler()
        return logging.getLogger(_ROOT_NAME).level

    @classmethod
    def parse_argv(cls, argv: list[str] | None = None) -> list[str]:
        """
        Apply ``-l/--log_level LEVEL`` from ``argv`` (default ``sys.argv[1:]``).

        Return the other args.
        """
        args = list(sys.argv[1:] if argv is None else argv)
        rest: list[str] = []
        i = 0
        while i < len(args):
            a = args[i]
            if a in ('-l', '--log_level', '--log-level'):
                if i + 1 >= len(args):
                    raise ValueError(f'option {a} needs a level: debug, info, warning or error')
                cls.set_level(args[i + 1])
                i += 2
                continue
            if a.startswith('--log_level=') or a.startswith('--log-level='):
                cls.set_level(a.split('=', 1)[1])
            else:
                rest.append(a)
            i += 1
        return rest
