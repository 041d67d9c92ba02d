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
objects the kernels do not know yet (contacts, wrench and torque tasks, balance, Cartesian
tasks in a moving base frame, anything with compute callbacks) run their Python update, in the
same order, into the same arrays: the solve that follows is the reference path's.

Lowered so far: CartesianTask (static base frame), JointAccelerationTask, CoMTask, MomentumTask,
the regularisation, torque / position (viable) / velocity / acceleration limits. Each lowered
object owns one row of the fill kernel's table (:mod:`.fill`); :meth:`_Lowered.step` runs its life
cycle and refreshes what the Python API may have replaced (a new servo, new limits) before the
kernel runs.
"""

from __future__ import annotations

import numpy as np

from . import fill, kernels
from ...common.task_base import ActivationState
from ...common.watched import Touched
from ...constraint.joint_limit_constraints import (
    JointAccelerationLimitConstraint,
    JointPositionLimitConstraint,
    JointTorqueLimitConstraint,
    JointVelocityLimitConstraint,
)
from ...task.cartesian_task import CartesianTask
from ...task.com_task import CoMTask
from ...task.joint_acceleration_task import JointAccelerationTask
from ...task.momentum_task import MomentumTask
from ...task.regularisation_task import RegularisationTask

_INACTIVE = (ActivationState.INIT, ActivationState.DEACTIVATED)
_ACTIVATED = ActivationState.ACTIVATED


def _rebind(owner, attr: str, record: np.ndarray, start: int) -> None:
    """Copy ``owner.attr`` into ``record[start:]`` and make the attribute a view on it."""
    value = np.asarray(getattr(owner, attr), dtype=float)
    view = record[start: start + value.size]
    view[:] = value.reshape(-1)
    setattr(owner, attr, view.reshape(value.shape))


def _rebind_blocks(task, record: np.ndarray, width: int, own, gains) -> None:
    """
    Rebind a servoed task's arrays and its PID's to blocks of ``width`` values of ``record``.

    ``own``: (attribute, block) of the task; ``gains``: the blocks of the PID's P, I, D gains,
    windup limit and integral.
    """
    for attr, block in own:
        _rebind(task, attr, record, width * block)
    for attr, block in zip(('_p', '_i', '_d', '_windup', '_integral'), gains):
        _rebind(task.pid(), attr, record, width * block)


def offset_in(view: np.ndarray, base: np.ndarray) -> int:
    """Index of ``view``'s first element (1-D base) or row (2-D base) in ``base``."""
    if not np.shares_memory(view, base):
        raise AssertionError("an object's rows are not the plan's")
    delta = view.__array_interface__['data'][0] - base.__array_interface__['data'][0]
    return delta // base.strides[0]


class Tables:
    """The fill kernel's records and table, sized for the lowered objects."""

    def __init__(self, lowered, robot):
        n, nv = robot.get_nr_of_degrees_of_freedom(), robot.model.nv
        count = {kind: sum(low.kind == kind for low in lowered) for kind in range(9)}
        limited = sum(low.kind in (fill.TORQUE, fill.POSITION, fill.VELOCITY,
                                   fill.ACCELERATION) for low in lowered)
        self.cart = np.zeros((max(1, count[fill.CART]), kernels.CART_SIZE))
        self.cart_sup = np.zeros((max(1, count[fill.CART]), nv), dtype=np.bool_)
        self.jrec = np.zeros((max(1, count[fill.JOINT]), kernels.JOINT_BLOCKS * n))
        self.lims = np.zeros((max(1, limited), 2, n))
        self.pacc = np.ones((max(1, limited), n))
        self.tab = np.zeros((max(1, len(lowered)), fill.TAB), dtype=np.int64)
        self.par = np.zeros((max(1, len(lowered)), 2))
        self.tmp = np.zeros(64 + n)
        self.crec = np.zeros((max(1, count[fill.COM]), kernels.COM_SIZE))
        self.mrec = np.zeros((max(1, count[fill.MOM]), kernels.MOM_SIZE))
        self.body = np.zeros((robot.model.njoints, 4))
        self.set_bodies(robot.model)
        self.next = {'cart': 0, 'joint': 0, 'lims': 0, 'com': 0, 'mom': 0}
        #: set when an object of this configuration (or its servo) changed an attribute
        self.watch = Touched()

    def set_bodies(self, model) -> None:
        """Each joint's body [mass, lever] (row 0: the total mass), from the model's inertias."""
        for j in range(1, model.njoints):
            inertia = model.inertias[j]
            self.body[j, 0] = inertia.mass
            self.body[j, 1:] = inertia.lever
        self.body[0, 0] = self.body[1:, 0].sum() or 1.0

    def take(self, what: str) -> int:
        i = self.next[what]
        self.next[what] += 1
        return i


class _Lowered:
    """One object computed by the fill kernel: its table row, its life cycle."""

    kind = -1

    def __init__(self, obj):
        self.obj = obj
        self._on = False  # the table's on flag, as last written
        self._par = None  # the table's scalar parameter, as last written

    def bind(self, tables: Tables, k: int, plan) -> None:
        self.tables, self.k = tables, k
        tables.tab[k, 0] = self.kind
        tables.tab[k, 1] = 0
        self.obj.watch_by(tables.watch)

    def step(self, t: float) -> None:
        """Advance the activation ramp (as TaskBase.update) and set the table's on flag."""
        obj = self.obj
        st = obj.state
        if st is _ACTIVATED:
            on = True
        elif st in _INACTIVE:
            on = False
        else:
            obj.step_ramp(t)
            on = obj.state not in _INACTIVE
        if on:
            self.refresh()
        if on is not self._on:  # numpy item writes are not free: only on a change
            self.tables.tab[self.k, 1] = on
            self._on = on

    def refresh(self) -> None:
        """Take what the Python API replaced since the last cycle (nothing by default)."""

    def rebind_model(self) -> None:
        """Take what this object read from the robot's model (a new one after a re-weld)."""

    def set_par(self, value: float) -> None:
        if value != self._par:
            self.tables.par[self.k, 0] = value
            self._par = value


class _Limited(_Lowered):
    """A limit constraint: its (lower, upper) pair lives in the tables (``_limits`` views)."""

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        self.a = tables.take('lims')
        tables.tab[k, 2] = self.a
        self._take_limits()

    def _take_limits(self) -> None:
        lo, hi = self.obj.limits
        pair = self.tables.lims[self.a]
        pair[0], pair[1] = lo, hi
        self.obj.limits = self.src = (pair[0], pair[1])

    def refresh(self) -> None:
        if self.obj.limits is not self.src:  # set_limits made a new pair
            self._take_limits()


class _Cartesian(_Lowered):
    kind = fill.CART

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        self.a = tables.take('cart')
        tables.tab[k, 2] = self.a
        self.plan = plan
        self._bind_servo()

    def _bind_servo(self) -> None:
        task, t = self.obj, self.tables
        robot = task.robot
        servo = self.servo = task.servo_controller()
        servo.watch_by(t.watch)
        pid = servo.pid()
        self.fid = servo.fid
        frame = robot.model.frames[self.fid]
        rec = t.cart[self.a]
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
        Tb = robot.static_base_placement()
        rec[kernels.BASE_R: kernels.BASE_R + 9] = Tb[:3, :3].reshape(-1)
        rec[kernels.BASE_P: kernels.BASE_P + 3] = Tb[:3, 3]
        support = t.cart_sup[self.a]
        support[:] = False
        for j in robot.model.supports[frame.parentJoint]:
            if j > 0:
                jm = robot.model.joints[j]
                support[jm.idx_v: jm.idx_v + jm.nv] = True
        t.tab[self.k, 3] = offset_in(task.E, self.plan.E)
        t.tab[self.k, 4] = frame.parentJoint

    def rebind_model(self) -> None:
        self._bind_servo()  # the frame's placement on its joint may have changed

    @staticmethod
    def lowerable(task, robot) -> str:
        if type(task) is not CartesianTask:
            return 'a task type the kernels do not know'
        if robot.static_base_placement() is None:
            return 'a Cartesian task in a moving base frame'
        if task.servo_controller().fid is None:
            return 'a Cartesian task without a control frame'
        return ''

    def refresh(self) -> None:
        servo = self.servo
        if servo is not self.obj.servo_controller() or servo.fid != self.fid:
            self._bind_servo()  # a new servo, or a new control frame
            servo = self.servo
        if not servo.has_desired():
            servo.hold_current_pose()  # a task switched on without a target holds its pose


class _Joint(_Lowered):
    kind = fill.JOINT

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        task = self.obj
        n = task.robot.get_nr_of_degrees_of_freedom()
        a = tables.take('joint')
        rec = tables.jrec[a]
        for attr, block in (('_q_ref', kernels.J_Q_REF), ('_qd_ref', kernels.J_QD_REF),
                            ('_qdd_ref', kernels.J_QDD_REF), ('_q_err', kernels.J_Q_ERR),
                            ('_qd_err', kernels.J_QD_ERR)):
            _rebind(task, attr, rec, block * n)
        pid = task.pid()
        for attr, block in (('_p', kernels.J_KP), ('_i', kernels.J_KI), ('_d', kernels.J_KD),
                            ('_windup', kernels.J_WINDUP), ('_integral', kernels.J_INTEGRAL)):
            _rebind(pid, attr, rec, block * n)
        tables.tab[k, 2] = a
        tables.tab[k, 3] = offset_in(task.f, plan.diag_f)

    def refresh(self) -> None:
        if not self.obj.has_desired():
            self.obj.hold_current_position()


class _CoM(_Lowered):
    kind = fill.COM

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        task = self.obj
        a = tables.take('com')
        own = (('_p_ref', kernels.C_P_REF), ('_v_ref', kernels.C_V_REF),
               ('_a_ref', kernels.C_A_REF), ('_err', kernels.C_ERR))
        gains = (kernels.C_KP, kernels.C_KI, kernels.C_KD, kernels.C_WINDUP, kernels.C_INTEGRAL)
        _rebind_blocks(task, tables.crec[a], 3, own, gains)
        tables.tab[k, 2] = a
        tables.tab[k, 3] = offset_in(task.E, plan.E)

    def refresh(self) -> None:
        task = self.obj
        if not task.has_desired():  # hold the CoM where it is when the task first computes
            task.robot.update_terms()
            task.set_desired(task.robot.data.com[0])


class _Momentum(_Lowered):
    kind = fill.MOM

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        task = self.obj
        a = tables.take('mom')
        own = (('_h_ref', kernels.M_H_REF), ('_hd_ref', kernels.M_HD_REF), ('_err', kernels.M_ERR))
        gains = (kernels.M_KP, kernels.M_KI, kernels.M_KD, kernels.M_WINDUP, kernels.M_INTEGRAL)
        _rebind_blocks(task, tables.mrec[a], 6, own, gains)
        tables.tab[k, 2] = a
        tables.tab[k, 3] = offset_in(task.E, plan.E)
        self.refresh()

    def refresh(self) -> None:
        self.set_par(1.0 / self.obj.robot.get_total_mass())  # (its rows are per unit of mass)

    def rebind_model(self) -> None:
        self.refresh()


class _Regularisation(_Lowered):
    kind = fill.REG

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        tables.tab[k, 3] = offset_in(self.obj.f, plan.diag_f)

    def refresh(self) -> None:
        self.set_par(self.obj.damping)


class _TorqueLimit(_Limited):
    kind = fill.TORQUE

    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        tables.tab[k, 3] = offset_in(self.obj.C, plan.M)


class _JointBox(_Limited):
    def bind(self, tables, k, plan) -> None:
        super().bind(tables, k, plan)
        tables.tab[k, 3] = offset_in(self.obj.lb, plan.box_lb)

    def refresh(self) -> None:
        super().refresh()
        self.set_par(getattr(self.obj, 'horizon', 0.0))


class _PositionLimit(_JointBox):
    kind = fill.POSITION
    _acc_of = None

    def refresh(self) -> None:
        super().refresh()
        acc = self.obj.max_acceleration
        if acc is not self._acc_of:  # set_max_acceleration made a new one
            self._acc_of = acc
            self.tables.pacc[self.a] = np.broadcast_to(acc, self.tables.pacc.shape[1])


class _VelocityLimit(_JointBox):
    kind = fill.VELOCITY


class _AccelerationLimit(_JointBox):
    kind = fill.ACCELERATION


_EXACT = {
    CoMTask: _CoM,
    MomentumTask: _Momentum,
    RegularisationTask: _Regularisation,
    JointAccelerationTask: _Joint,
    JointTorqueLimitConstraint: _TorqueLimit,
    JointPositionLimitConstraint: _PositionLimit,
    JointVelocityLimitConstraint: _VelocityLimit,
    JointAccelerationLimitConstraint: _AccelerationLimit,
}


def lower(obj):
    """Return the kernel-side object of ``obj``, or (None, why it stays in Python)."""
    if obj.compute_begin_cb is not None or obj.compute_end_cb is not None:
        return None, 'compute callbacks'
    if isinstance(obj, CartesianTask):
        why = _Cartesian.lowerable(obj, obj.robot)
        return (None, why) if why else (_Cartesian(obj), '')
    make = _EXACT.get(type(obj))
    if make is None:
        return None, f'{type(obj).__name__} not lowered yet'
    return make(obj), ''
