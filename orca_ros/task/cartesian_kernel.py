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
The Cartesian task's compiled form: its record, its row kernel, its lowering.

:func:`cartesian_rows` computes what :class:`.cartesian_task.CartesianTask` and its
:class:`~orca_ros.servo.cartesian_acceleration_pid.CartesianAccelerationPID` compute in Python,
formula for formula: the frame's pose, velocity, Jacobian and bias acceleration from the joint's
placement, velocity and drift in Pinocchio's Data, then the servo's pose and velocity errors, its
PID and the rows ``E = J``, ``f = a_des - J_dot nu``. :class:`CartesianLowered` keeps the
servo's and its PID's arrays in the task's record (offsets below) at configuration.

Lowered where the base frame is static (the world, or a frame fixed in it) and the servo has a
control frame; any other Cartesian task runs its Python update.
"""

from __future__ import annotations

from .cartesian_task import CartesianTask
from ..common.lowered import CART, Lowered, offset_in
from ..math.rotations_kernel import log3
from ..servo.pid_kernel import pid_command
from ..utils.jit import njit

# the task's float record: the servo's arrays, its PID's (blocks of 6), the frame's placement on
# its joint and the base frame's placement in the world
POSE_REF, VEL_REF, ACC_REF = 0, 16, 22
KP, KI, KD, WINDUP, INTEGRAL = 28, 34, 40, 46, 52
POSE, VEL, POSE_ERR, VEL_ERR, CMD = 58, 74, 80, 86, 92
FRAME_R, FRAME_P, BASE_R, BASE_P = 98, 107, 110, 119
SIZE = 122


@njit
def cartesian_rows(rec, R_j, p_j, v_j, a_j, J, support, E, f, row, dt, tmp):
    """
    One Cartesian task: its servo (error, PID, command into rec) and its rows E[row:row+6], f.

    Frame terms as FrameApiMixin.frame_terms in a static base frame (BASE_R, BASE_P; identity
    for the world): pose, LOCAL_WORLD_ALIGNED Jacobian (support columns of data.J shifted to the
    frame's origin), velocity J v and classical bias acceleration from the joint's drift data.a.
    """
    nv = J.shape[1]
    # frame placement in the world: oMi[j] * placement
    Rf = tmp[0:9].reshape(3, 3)
    pf = tmp[9:12]
    for r in range(3):
        for c in range(3):
            s = 0.0
            for k in range(3):
                s += R_j[r, k] * rec[FRAME_R + 3 * k + c]
            Rf[r, c] = s
        s = p_j[r]
        for k in range(3):
            s += R_j[r, k] * rec[FRAME_P + k]
        pf[r] = s
    # the joint's spatial velocity and drift, shifted to the frame's origin (joint axes) and
    # rotated into the world: v_lin' = v + w x r, a_lin' = a + dw x r
    vl, wl, al, dwl = tmp[12:15], tmp[15:18], tmp[18:21], tmp[21:24]
    rx, ry, rz = rec[FRAME_P], rec[FRAME_P + 1], rec[FRAME_P + 2]
    w0, w1, w2 = v_j[3], v_j[4], v_j[5]
    b0, b1, b2 = a_j[3], a_j[4], a_j[5]
    lin_v0 = v_j[0] + w1 * rz - w2 * ry
    lin_v1 = v_j[1] + w2 * rx - w0 * rz
    lin_v2 = v_j[2] + w0 * ry - w1 * rx
    lin_a0 = a_j[0] + b1 * rz - b2 * ry
    lin_a1 = a_j[1] + b2 * rx - b0 * rz
    lin_a2 = a_j[2] + b0 * ry - b1 * rx
    for r in range(3):
        vl[r] = R_j[r, 0] * lin_v0 + R_j[r, 1] * lin_v1 + R_j[r, 2] * lin_v2
        wl[r] = R_j[r, 0] * w0 + R_j[r, 1] * w1 + R_j[r, 2] * w2
        al[r] = R_j[r, 0] * lin_a0 + R_j[r, 1] * lin_a1 + R_j[r, 2] * lin_a2
        dwl[r] = R_j[r, 0] * b0 + R_j[r, 1] * b1 + R_j[r, 2] * b2
    # classical acceleration: a_lin + w x v_lin
    al[0] += wl[1] * vl[2] - wl[2] * vl[1]
    al[1] += wl[2] * vl[0] - wl[0] * vl[2]
    al[2] += wl[0] * vl[1] - wl[1] * vl[0]
    # in the base frame: R_b^T (x - p_b) for the position, R_b^T for every vector
    Rb = rec[BASE_R: BASE_R + 9].reshape(3, 3)
    pose = rec[POSE: POSE + 16].reshape(4, 4)
    vel = rec[VEL: VEL + 6]
    bias = tmp[24:30]
    for r in range(3):
        for c in range(3):
            s = 0.0
            for k in range(3):
                s += Rb[k, r] * Rf[k, c]
            pose[r, c] = s
        s = 0.0
        for k in range(3):
            s += Rb[k, r] * (pf[k] - rec[BASE_P + k])
        pose[r, 3] = s
        pose[3, r] = 0.0
        vel[r] = Rb[0, r] * vl[0] + Rb[1, r] * vl[1] + Rb[2, r] * vl[2]
        vel[3 + r] = Rb[0, r] * wl[0] + Rb[1, r] * wl[1] + Rb[2, r] * wl[2]
        bias[r] = Rb[0, r] * al[0] + Rb[1, r] * al[1] + Rb[2, r] * al[2]
        bias[3 + r] = Rb[0, r] * dwl[0] + Rb[1, r] * dwl[1] + Rb[2, r] * dwl[2]
    pose[3, 3] = 1.0
    # Jacobian: world columns of the support, linear part shifted to the frame's origin
    for col in range(nv):
        if not support[col]:
            for r in range(6):
                E[row + r, col] = 0.0
            continue
        j0, j1, j2 = J[0, col], J[1, col], J[2, col]
        k0, k1, k2 = J[3, col], J[4, col], J[5, col]
        l0 = j0 + k1 * pf[2] - k2 * pf[1]
        l1 = j1 + k2 * pf[0] - k0 * pf[2]
        l2 = j2 + k0 * pf[1] - k1 * pf[0]
        for r in range(3):
            E[row + r, col] = Rb[0, r] * l0 + Rb[1, r] * l1 + Rb[2, r] * l2
            E[row + 3 + r, col] = Rb[0, r] * k0 + Rb[1, r] * k1 + Rb[2, r] * k2
    # servo: pose error [p_ref - p, log(R_ref R^T)], velocity error, PID, + acc_ref
    ref = rec[POSE_REF: POSE_REF + 16].reshape(4, 4)
    pe = rec[POSE_ERR: POSE_ERR + 6]
    ve = rec[VEL_ERR: VEL_ERR + 6]
    Rerr = tmp[30:39].reshape(3, 3)
    for r in range(3):
        pe[r] = ref[r, 3] - pose[r, 3]
        for c in range(3):
            Rerr[r, c] = ref[r, 0] * pose[c, 0] + ref[r, 1] * pose[c, 1] + ref[r, 2] * pose[c, 2]
    log3(Rerr, tmp[39:42], tmp[42:51].reshape(3, 3))
    pe[3], pe[4], pe[5] = tmp[39], tmp[40], tmp[41]
    for r in range(6):
        ve[r] = rec[VEL_REF + r] - vel[r]
    cmd = rec[CMD: CMD + 6]
    pid_command(rec, KP, KI, KD, WINDUP, INTEGRAL, pe, ve, 6, dt, cmd)
    for r in range(6):
        cmd[r] += rec[ACC_REF + r]
        f[row + r] = cmd[r] - bias[r]


class CartesianLowered(Lowered):
    """A Cartesian task in the fill kernel's table: its record in ``tables.cart``."""

    kind = CART
    lowers = CartesianTask

    @staticmethod
    def lowerable(task, robot) -> str:
        if robot.static_base_placement() is None:
            return 'a Cartesian task in a moving base frame'
        if task.servo_controller().fid is None:
            return 'a Cartesian task without a control frame'
        return ''

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
        self.fid = servo.fid
        frame = robot.model.frames[self.fid]
        rec = t.cart[self.a]
        servo.keep_in(rec, {
            'pose_ref': POSE_REF, 'vel_ref': VEL_REF, 'acc_ref': ACC_REF, 'pose': POSE,
            'vel': VEL, 'pose_err': POSE_ERR, 'vel_err': VEL_ERR, 'cmd': CMD,
        })
        servo.pid().keep_in(rec, (KP, KI, KD, WINDUP, INTEGRAL))
        rec[FRAME_R: FRAME_R + 9] = frame.placement.rotation.reshape(-1)
        rec[FRAME_P: FRAME_P + 3] = frame.placement.translation
        Tb = robot.static_base_placement()
        rec[BASE_R: BASE_R + 9] = Tb[:3, :3].reshape(-1)
        rec[BASE_P: BASE_P + 3] = Tb[:3, 3]
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

    def refresh(self) -> None:
        servo = self.servo
        if servo is not self.obj.servo_controller() or servo.fid != self.fid:
            self._bind_servo()  # a new servo, or a new control frame
            servo = self.servo
        if not servo.has_desired():
            servo.hold_current_pose()  # a task switched on without a target holds its pose
