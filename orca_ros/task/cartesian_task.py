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
Cartesian acceleration task.

J nu_dot + J_dot nu = a_des, a_des from a CartesianAccelerationPID.
"""

from __future__ import annotations

from .generic_task import GenericTask
from ..servo.cartesian_acceleration_pid import CartesianAccelerationPID


class CartesianTask(GenericTask):
    def __init__(self, name: str):
        super().__init__(name)
        self._servo = CartesianAccelerationPID(f'{name}_servo')

    def rows(self) -> int:
        return 6

    def set_robot_model(self, robot) -> None:
        super().set_robot_model(robot)
        self._servo.set_robot_model(robot)

    def set_servo_controller(self, servo: CartesianAccelerationPID) -> None:
        self._servo = servo
        if self.robot is not None:
            servo.set_robot_model(self.robot)

    def servo_controller(self) -> CartesianAccelerationPID:
        return self._servo

    def set_control_frame(self, frame: str) -> None:
        self._servo.set_control_frame(frame)

    def get_control_frame(self) -> str | None:
        return self._servo.get_control_frame()

    def _update_affine_function(self, current_time: float, dt: float) -> None:
        servo = self._servo
        # a task switched on without a target holds where the frame is when it first computes
        if not servo.has_desired():
            servo.hold_current_pose()
        a_des = servo.update(current_time, dt)
        _, J, _, bias = self.robot.frame_terms(servo.fid)
        lay = self.layout
        self.E[:, lay.acc] = J
        self.f[:] = a_des - bias
