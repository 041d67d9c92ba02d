"""Cartesian acceleration task: J nu_dot + J_dot nu = a_des, a_des from a CartesianAccelerationPID."""
from __future__ import annotations

from ..servo.cartesian_acceleration_pid import CartesianAccelerationPID
from .generic_task import GenericTask


class CartesianTask(GenericTask):
    def __init__(self, name: str):
        super().__init__(name)
        self._servo = CartesianAccelerationPID(f"{name}_servo")

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
        _, J, _, bias = self.robot.frame_terms(servo._fid)
        lay = self.layout
        self.E[:, lay.acc] = J
        self.f[:] = a_des - bias
