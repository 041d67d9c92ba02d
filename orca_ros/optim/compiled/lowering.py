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
Lowering: at configuration, each task and constraint the kernels know becomes packed arrays.

A lowered object's parameters and state live in one float record; the object's own arrays
(targets, gains, the servo's pose and errors) are rebound to views on that record, so that the
Python API (``set_desired``, ``pid().set_proportional_gain``, ``get_cartesian_pose_error``…) reads
and writes what the kernels use, with no copy per cycle. Its rows are the plan's (the same views
the reference path writes through). Every cycle the kernels fill the lowered objects' rows; the
objects the kernels do not know yet (contacts, CoM, wrench and torque tasks, balance, Cartesian
tasks in a moving base frame, anything with compute callbacks) run their Python update, in the
same order, into the same arrays: the solve that follows is the reference path's.

Lowered so far: CartesianTask (static base frame), JointAccelerationTask, the regularisation,
torque / position (viable) / velocity / acceleration limits.
"""

from __future__ import annotations

import numpy as np

from ...common.task_base import ActivationState
from ...constraint.joint_limit_constraints import (
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)
from ...task.cartesian_task import CartesianTask
from ...task.joint_acceleration_task import JointAccelerationTask
from ...task.regularisation_task import RegularisationTask

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)


def _rebind(owner, attr: str, record: np.ndarray, start: int, shape=None):
    """Copy ``owner.attr`` into ``record[start:]`` and make the attribute a view on it."""
    value = np.asarray(getattr(owner, attr), dtype=float)
    view = record[start: start + value.size]
    view[:] = value.reshape(-1)
    setattr(owner, attr, view.reshape(value.shape if shape is None else shape))


class _Lowered:
    """One object computed by a kernel: its life cycle runs here, its values in ``fill``."""

    def __init__(self, obj):
        self.obj = obj

    def step(self, t: float) -> bool:
        """Advance the activation ramp (as TaskBase.update); True when the object computes."""
        obj = self.obj
        st = obj.state
        if st is ActivationState.ACTIVATED:
            return True
        if st in _INACTIVE:
            return False
        obj._step_ramp(t)
        return obj.state not in _INACTIVE

    def fill(self, t: float, dt: float) -> None:
        raise NotImplementedError


class _Cartesian(_Lowered):
    def __init__(self, task, plan, kernels):
        super().__init__(task)
        self.k = kernels
        self.plan = plan
        self._bind(task)
        self.tmp = np.zeros(64)

    def _bind(self, task) -> None:
        """Rebind the servo's arrays to the record and take the frame's live views."""
        kernels, plan = self.k, self.plan
        robot = task.robot
        servo, pid = task.servo_controller(), task.servo_controller().pid()
        self.servo = servo
        self.fid = servo._fid
        frame = robot.model.frames[self.fid]
        joint = frame.parentJoint
        d = robot.data
        rec = self.rec = np.zeros(kernels.CART_SIZE)
        for attr, start in (('_pose_ref', kernels.POSE_REF), ('_vel_ref', kernels.VEL_REF),
                            ('_acc_ref', kernels.ACC_REF), ('_pose', kernels.POSE),
                            ('_vel', kernels.VEL), ('_pose_err', kernels.POSE_ERR),
                            ('_vel_err', kernels.VEL_ERR), ('_cmd', kernels.CMD)):
            _rebind(servo, attr, rec, start)
        for attr, start in (('_p', kernels.KP), ('_i', kernels.KI), ('_d', kernels.KD),
                            ('_windup', kernels.WINDUP), ('_integral', kernels.INTEGRAL)):
            _rebind(pid, attr, rec, start)
        rec[kernels.FRAME_R: kernels.FRAME_R + 9] = frame.placement.rotation.reshape(-1)
        rec[kernels.FRAME_P: kernels.FRAME_P + 3] = frame.placement.translation
        Tb = np.eye(4) if robot._base_is_world else robot._base_static_T
        rec[kernels.BASE_R: kernels.BASE_R + 9] = Tb[:3, :3].reshape(-1)
        rec[kernels.BASE_P: kernels.BASE_P + 3] = Tb[:3, 3]
        # live views on Pinocchio's Data: valid as long as the Data lives (the robot's)
        self.R, self.p = d.oMi[joint].rotation, d.oMi[joint].translation
        self.v, self.a = d.v[joint].vector, d.a[joint].vector
        self.J = d.J
        self.support = np.zeros(robot.model.nv, dtype=np.bool_)
        for j in robot.model.supports[joint]:
            if j > 0:
                jm = robot.model.joints[j]
                self.support[jm.idx_v: jm.idx_v + jm.nv] = True
        self.E, self.f = plan.E, plan.f
        if not np.shares_memory(task.E, plan.E):
            raise AssertionError(f"task '{task.name}': its rows are not the plan's")
        self.row = _row_of(task.E, plan.E)

    @staticmethod
    def lowerable(task, robot) -> str:
        if type(task) is not CartesianTask:
            return 'a task type the kernels do not know'
        if not (robot._base_is_world or robot._base_static):
            return 'a Cartesian task in a moving base frame'
        if task.servo_controller()._fid is None:
            return 'a Cartesian task without a control frame'
        return ''

    def fill(self, t: float, dt: float) -> None:
        servo = self.servo
        if servo is not self.obj._servo or servo._fid != self.fid:
            self._bind(self.obj)  # a new servo, or a new control frame
            servo = self.servo
        if not servo._has_desired:
            servo.hold_current_pose()  # a task switched on without a target holds its pose
        self.k.cartesian_rows(
            self.rec, self.R, self.p, self.v, self.a, self.J, self.support, self.E, self.f,
            self.row, dt, self.tmp,
        )


def _row_of(view: np.ndarray, base: np.ndarray) -> int:
    """First row of ``view`` (a row slice of the C-contiguous 2-D ``base``)."""
    offset = view.__array_interface__['data'][0] - base.__array_interface__['data'][0]
    return offset // base.strides[0]


class _Joint(_Lowered):
    def __init__(self, task, kernels):
        super().__init__(task)
        self.k = kernels
        n = self.n = task.robot.get_nr_of_degrees_of_freedom()
        rec = self.rec = np.zeros(kernels.JOINT_BLOCKS * n)
        for attr, block in (('_q_ref', kernels.J_Q_REF), ('_qd_ref', kernels.J_QD_REF),
                            ('_qdd_ref', kernels.J_QDD_REF), ('_q_err', kernels.J_Q_ERR),
                            ('_qd_err', kernels.J_QD_ERR)):
            _rebind(task, attr, rec, block * n)
        pid = task.pid()
        for attr, block in (('_p', kernels.J_KP), ('_i', kernels.J_KI), ('_d', kernels.J_KD),
                            ('_windup', kernels.J_WINDUP), ('_integral', kernels.J_INTEGRAL)):
            _rebind(pid, attr, rec, block * n)
        self.q, self.v = task.robot._q, task.robot._v
        self.tmp = np.zeros(n)

    @staticmethod
    def lowerable(task, robot) -> str:
        return '' if type(task) is JointAccelerationTask else 'a task type the kernels do not know'

    def fill(self, t: float, dt: float) -> None:
        task = self.obj
        if not task._has_desired:
            task.hold_current_position()
        self.k.joint_rows(self.rec, self.n, self.q, self.v, task.f, dt, self.tmp)


class _Regularisation(_Lowered):
    def __init__(self, task, kernels):
        super().__init__(task)
        lay = task.layout
        self.f_acc = task.f[lay.acc]
        self.v = task.robot._v_pin

    def fill(self, t: float, dt: float) -> None:
        task = self.obj
        if task.damping:
            np.multiply(self.v, -task.damping, out=self.f_acc)
        else:
            self.f_acc.fill(0.0)


class _TorqueLimit(_Lowered):
    def fill(self, t: float, dt: float) -> None:
        c = self.obj
        lay = c.layout
        c.C[:] = lay.T
        lo, hi = c._limits
        np.subtract(lo, lay.t0, out=c.lb)
        np.subtract(hi, lay.t0, out=c.ub)


class _PositionLimit(_Lowered):
    def __init__(self, c, kernels):
        super().__init__(c)
        self.k = kernels
        self.q, self.v = c.robot._q, c.robot._v
        self._acc_of = None

    def fill(self, t: float, dt: float) -> None:
        c = self.obj
        if self._acc_of is not c.max_acceleration:  # set_max_acceleration rebinds it
            self._acc_of = c.max_acceleration
            self.acc = np.array(np.broadcast_to(c.max_acceleration, self.q.size), dtype=float)
        lo, hi = c._limits
        self.k.position_box(self.q, self.v, lo, hi, self.acc, dt, c.horizon, c.lb, c.ub)


class _VelocityLimit(_Lowered):
    def __init__(self, c, kernels):
        super().__init__(c)
        self.v = c.robot._v

    def fill(self, t: float, dt: float) -> None:
        c = self.obj
        h = max(c.horizon, dt)
        lo, hi = c._limits
        np.multiply(lo - self.v, 1.0 / h, out=c.lb)
        np.multiply(hi - self.v, 1.0 / h, out=c.ub)


class _AccelerationLimit(_Lowered):
    def fill(self, t: float, dt: float) -> None:
        c = self.obj
        c.lb[:], c.ub[:] = c._limits


def _has_callbacks(obj) -> bool:
    return obj._cb_begin is not None or obj._cb_end is not None


def lower(obj, plan, kernels):
    """Return the kernel-side object of ``obj``, or (None, why it stays in Python)."""
    if _has_callbacks(obj):
        return None, 'compute callbacks'
    robot = obj.robot
    if isinstance(obj, CartesianTask):
        why = _Cartesian.lowerable(obj, robot)
        return (None, why) if why else (_Cartesian(obj, plan, kernels), '')
    if isinstance(obj, JointAccelerationTask):
        why = _Joint.lowerable(obj, robot)
        return (None, why) if why else (_Joint(obj, kernels), '')
    exact = {
        RegularisationTask: lambda: _Regularisation(obj, kernels),
        JointTorqueLimitConstraint: lambda: _TorqueLimit(obj),
        JointPositionLimitConstraint: lambda: _PositionLimit(obj, kernels),
        JointVelocityLimitConstraint: lambda: _VelocityLimit(obj, kernels),
        JointAccelerationLimitConstraint: lambda: _AccelerationLimit(obj),
    }
    make = exact.get(type(obj))
    if make is None:
        return None, f'{type(obj).__name__} not lowered yet'
    return make(), ''
