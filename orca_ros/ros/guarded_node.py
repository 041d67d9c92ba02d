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
A Node whose callbacks cannot kill it.

Every subscription, timer and service callback created through this class is wrapped: an exception
is logged (throttled, naming the callback and the cause) and the node carries on. Timers call
:meth:`GuardedNode.on_callback_error` so a node can fall back to a safe output (the controller
sends its safe command); services answer ``success = False`` with the reason instead of leaving the
caller waiting.
"""

from __future__ import annotations

from rclpy.node import Node

from ..utils.throttled_log import ThrottledLog


class GuardedNode(Node):
    def __init__(self, name: str, **kwargs):
        super().__init__(name, **kwargs)
        self.say = ThrottledLog(self.get_logger(), period=1.0)

    def on_callback_error(self, what: str, exc: Exception) -> None:
        """
        React safely after a callback raised.

        A hook; by default nothing beyond the log line.
        """

    def say_raised(self, what: str, exc: Exception) -> None:
        """Log, throttled per ``what``, that ``what`` (a callback, a job) raised ``exc``."""
        self.say('error', f'raised:{what}', f'{what} raised {type(exc).__name__}: {exc}')

    def _guard(self, what: str, fn, service: bool = False):
        def call(*args):
            try:
                return fn(*args)
            except Exception as exc:  # noqa: BLE001 - the point: nothing escapes into the executor
                self.say_raised(what, exc)
                try:
                    self.on_callback_error(what, exc)
                except Exception as exc2:  # noqa: BLE001
                    self.say(
                        'error',
                        'raised:on_callback_error',
                        f'safe reaction raised {type(exc2).__name__}: {exc2}',
                    )
                if service:
                    res = args[1]
                    if hasattr(res, 'success'):
                        res.success = False
                    if hasattr(res, 'message'):
                        res.message = f'failed: {type(exc).__name__}: {exc}'
                    return res
                return None

        return call

    def create_subscription(self, msg_type, topic, callback, qos_profile, **kwargs):
        return super().create_subscription(
            msg_type, topic, self._guard(f"message on '{topic}'", callback), qos_profile, **kwargs
        )

    def create_timer(self, timer_period_sec, callback, *args, **kwargs):
        name = getattr(callback, '__name__', 'timer').lstrip('_')
        return super().create_timer(
            timer_period_sec, self._guard(f"timer '{name}'", callback), *args, **kwargs
        )

    def create_service(self, srv_type, srv_name, callback, **kwargs):
        return super().create_service(
            srv_type, srv_name, self._guard(f"service '{srv_name}'", callback, True), **kwargs
        )
