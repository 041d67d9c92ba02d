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
Activation life cycle shared by tasks and constraints.

States: INIT -> (activate) ACTIVATING -> ACTIVATED -> (deactivate) DEACTIVATING -> DEACTIVATED. The
ramp factor follows :func:`orca_ros.math.smooth_ramp` over ``ramp_duration`` seconds of controller
time (0 -> 1 while activating, back to 0 while deactivating). A deactivation requested in the
middle of an activation runs the ramp backwards from where it is, so the factor never jumps.

Callbacks (each optional): activation() when activate() is called, activated() when the ramp
reaches 1, compute_begin(t, dt) / compute_end(t, dt) around every computation while not inactive,
deactivation() when deactivate() is called, deactivated() when the ramp reaches 0.
"""

from __future__ import annotations

from enum import Enum
from typing import Callable

from .watched import Watched
from ..math.smooth_ramp import smooth_ramp
from ..utils.logger import get_logger

_LOG = get_logger('task')


class ActivationState(Enum):
    INIT = 'init'
    ACTIVATING = 'activating'
    ACTIVATED = 'activated'
    DEACTIVATING = 'deactivating'
    DEACTIVATED = 'deactivated'


_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)
_SNAP = 1e-9  # accumulated time steps rarely land exactly on the ramp's end


class TaskBase(Watched):
    def __init__(self, name: str):
        if not isinstance(name, str) or not name:
            raise ValueError('a task or constraint needs a non-empty name')
        self.name = name
        self.robot = None
        self.state = ActivationState.INIT
        self.ramp_duration = 0.0
        self._ramp_x = 0.0  # normalised ramp time in [0, 1]
        self.ramp_factor = 0.0
        self._ramp_t0: float | None = None
        self._ramp_x0 = 0.0
        self._cb_activation: Callable[[], None] | None = None
        self._cb_activated: Callable[[], None] | None = None
        self._cb_deactivation: Callable[[], None] | None = None
        self._cb_deactivated: Callable[[], None] | None = None
        self.compute_begin_cb: Callable[[float, float], None] | None = None
        self.compute_end_cb: Callable[[float, float], None] | None = None

    # -------------------------------------------------------------- configuration
    def set_robot_model(self, robot) -> None:
        self.robot = robot

    def set_ramp_duration(self, seconds: float) -> None:
        seconds = float(seconds)
        if not seconds >= 0.0:
            raise ValueError(f'{self.name}: ramp duration must be >= 0, got {seconds}')
        self.ramp_duration = seconds

    def get_ramp_duration(self) -> float:
        return self.ramp_duration

    def on_activation_callback(self, cb: Callable[[], None]) -> None:
        self._cb_activation = cb

    def on_activated_callback(self, cb: Callable[[], None]) -> None:
        self._cb_activated = cb

    def on_compute_begin_callback(self, cb: Callable[[float, float], None]) -> None:
        self.compute_begin_cb = cb

    def on_compute_end_callback(self, cb: Callable[[float, float], None]) -> None:
        self.compute_end_cb = cb

    def on_deactivation_callback(self, cb: Callable[[], None]) -> None:
        self._cb_deactivation = cb

    def on_deactivated_callback(self, cb: Callable[[], None]) -> None:
        self._cb_deactivated = cb

    # -------------------------------------------------------------- state
    def get_state(self) -> ActivationState:
        return self.state

    def is_activated(self) -> bool:
        return self.state is ActivationState.ACTIVATED

    def is_deactivated(self) -> bool:
        return self.state in _INACTIVE

    def is_computing(self) -> bool:
        """
        Tell whether the object contributes to the problem.

        True while activating, activated or deactivating.
        """
        return self.state not in _INACTIVE

    def get_ramp_value(self) -> float:
        return self.ramp_factor

    def activate(self) -> bool:
        if self.state in (ActivationState.ACTIVATING, ActivationState.ACTIVATED):
            return False
        self._ramp_x0 = self._ramp_x
        self._ramp_t0 = None
        self.state = ActivationState.ACTIVATING
        if self._cb_activation is not None:
            self._cb_activation()
        return True

    def deactivate(self) -> bool:
        if self.state not in (ActivationState.ACTIVATING, ActivationState.ACTIVATED):
            return False
        self._ramp_x0 = self._ramp_x
        self._ramp_t0 = None
        self.state = ActivationState.DEACTIVATING
        if self._cb_deactivation is not None:
            self._cb_deactivation()
        return True

    def step_ramp(self, t: float) -> None:
        """Advance the activation ramp to time ``t``; finish the state change when it ends."""
        st = self.state
        if st is ActivationState.ACTIVATING:
            if self._ramp_t0 is None:
                self._ramp_t0 = t
            T = self.ramp_duration
            x = 1.0 if T <= 0.0 else self._ramp_x0 + (t - self._ramp_t0) / T
            x = 1.0 if x >= 1.0 - _SNAP else x
            self._ramp_x = x
            self.ramp_factor = smooth_ramp(x)
            if x >= 1.0:
                self.state = ActivationState.ACTIVATED
                if self._cb_activated is not None:
                    self._cb_activated()
        elif st is ActivationState.DEACTIVATING:
            if self._ramp_t0 is None:
                self._ramp_t0 = t
            T = self.ramp_duration
            x = 0.0 if T <= 0.0 else self._ramp_x0 - (t - self._ramp_t0) / T
            x = 0.0 if x <= _SNAP else x
            self._ramp_x = x
            self.ramp_factor = smooth_ramp(x)
            if x <= 0.0:
                self.state = ActivationState.DEACTIVATED
                if self._cb_deactivated is not None:
                    self._cb_deactivated()

    def update(self, current_time: float, dt: float) -> None:
        """Advance the life cycle and recompute this object's contribution for the robot state."""
        st = self.state
        if (st is ActivationState.ACTIVATED and self.compute_begin_cb is None
                and self.compute_end_cb is None):
            self._update(current_time, dt)  # the steady state: nothing to ramp, nobody to call
            return
        if st in _INACTIVE:
            return
        if self.compute_begin_cb is not None:
            self.compute_begin_cb(current_time, dt)
        self.step_ramp(current_time)
        # the deactivating step may have just finished: the contribution is then zero, nothing to
        # compute
        if self.state not in _INACTIVE:
            self._update(current_time, dt)
        if self.compute_end_cb is not None:
            self.compute_end_cb(current_time, dt)

    def _update(self, current_time: float, dt: float) -> None:
        raise NotImplementedError

    def describe(self) -> str:
        state = f'{self.state.value}, ramp {self.ramp_factor:.3f}'
        return f"{type(self).__name__} '{self.name}' [{state}]"
