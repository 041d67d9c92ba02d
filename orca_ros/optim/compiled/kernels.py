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
The compiled cycle's kernels (numba): one pass fills every lowered task's and constraint's rows.

The arrays are those of the reference path (the plan's stacked rows, the objects' own buffers,
Pinocchio's Data), so that both paths feed the same solve; what the kernels compute is what the
Python objects compute, formula for formula (``test_compiled_cycle.py`` holds them to the same
torques). Packed layouts are described in :mod:`.lowering`.
"""

from __future__ import annotations

import math

import numpy as np

from ...utils.jit import njit

# the per-task float record of a Cartesian task (see lowering.CartesianRecord)
POSE_REF, VEL_REF, ACC_REF = 0, 16, 22
KP, KI, KD, WINDUP, INTEGRAL = 28, 34, 40, 46, 52
POSE, VEL, POSE_ERR, VEL_ERR, CMD = 58, 74, 80, 86, 92
FRAME_R, FRAME_P, BASE_R, BASE_P = 98, 107, 110, 119
CART_SIZE = 122

# the per-task float record of a joint acceleration task (blocks of n: see lowering.JointRecord)
J_Q_REF, J_QD_REF, J_QDD_REF, J_KP, J_KI, J_KD, J_WINDUP, J_INTEGRAL, J_Q_ERR, J_QD_ERR = range(10)
JOINT_BLOCKS = 10

# the per-task float record of a CoM task (blocks of 3)
C_P_REF, C_V_REF, C_A_REF, C_KP, C_KI, C_KD, C_WINDUP, C_INTEGRAL, C_ERR = range(9)
COM_SIZE = 27

# the per-task float record of a momentum task (blocks of 6)
M_H_REF, M_HD_REF, M_KP, M_KI, M_KD, M_WINDUP, M_INTEGRAL, M_ERR = range(8)
MOM_SIZE = 48

_FAR = 1e6  # as viable_bound._FAR
MARGIN_SHARE = 0.5  # as viable_bound._MARGIN_SHARE


_EPS = np.finfo(np.float64).eps
_PREC = _EPS ** (1.0 / 3.0)  # Pinocchio's Taylor precision of degree 2


@njit
def _theta_axis(i0, val, N, axis):
    """Angle and unit axis near pi from the diagonal entry ``i0`` (the largest); axis in place."""
    i1, i2 = (i0 + 1) % 3, (i0 + 2) % 3
    s = math.sqrt(val + _EPS + _EPS * _EPS) * (1.0 if N[i2, i1] >= N[i1, i2] else -1.0)
    axis[i0] = s / 2.0
    axis[i1] = 1.0 / (2.0 * s) * (N[i1, i0] + N[i0, i1])
    axis[i2] = 1.0 / (2.0 * s) * (N[i2, i0] + N[i0, i2])
    w = 1.0 / (2.0 * s) * (N[i2, i1] - N[i1, i2])
    norm = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    for k in range(3):
        axis[k] /= norm
    return 2.0 * math.atan2(norm, w)


@njit
def log3(R, out, N):
    """
    Rotation vector of R into out[0:3], by the scheme of the pinned Pinocchio's log3.

    R re-orthonormalised (into N, 3x3 scratch); theta from acos away from 0 and pi, from its
    expansion near them; the vector from the skew part scaled by theta / sin(theta), except near
    pi, where the axis comes from the largest diagonal entry.
    """
    n0 = math.sqrt(R[0, 0] ** 2 + R[1, 0] ** 2 + R[2, 0] ** 2)
    n1 = math.sqrt(R[0, 1] ** 2 + R[1, 1] ** 2 + R[2, 1] ** 2)
    for r in range(3):
        N[r, 0] = R[r, 0] / n0
        N[r, 1] = R[r, 1] / n1
    N[0, 2] = N[1, 0] * N[2, 1] - N[2, 0] * N[1, 1]
    N[1, 2] = N[2, 0] * N[0, 1] - N[0, 0] * N[2, 1]
    N[2, 2] = N[0, 0] * N[1, 1] - N[1, 0] * N[0, 1]
    N[0, 0] = N[1, 1] * N[2, 2] - N[2, 1] * N[1, 2]
    N[1, 0] = N[2, 1] * N[0, 2] - N[0, 1] * N[2, 2]
    N[2, 0] = N[0, 1] * N[1, 2] - N[1, 1] * N[0, 2]
    tr = N[0, 0] + N[1, 1] + N[2, 2]
    cos_value = (tr - 1.0) / 2.0
    if cos_value < -1.0 + _PREC:  # near pi
        v0, v1, v2 = 2.0 * N[0, 0] - tr + 1.0, 2.0 * N[1, 1] - tr + 1.0, 2.0 * N[2, 2] - tr + 1.0
        if v0 >= v1:
            i0, val = (0, v0) if v0 >= v2 else (2, v2)
        else:
            i0, val = (1, v1) if v1 >= v2 else (2, v2)
        theta = _theta_axis(i0, val, N, out)
        for k in range(3):
            out[k] *= theta
        return
    acos_expansion = math.sqrt(2.0 * (1.0 - cos_value) + _EPS * _EPS)
    if tr <= 3.0 - _PREC:
        theta = math.acos(cos_value) if tr >= -1.0 + _PREC else math.pi - acos_expansion
    else:
        theta = acos_expansion
    a0 = 0.5 * (N[2, 1] - N[1, 2])
    a1 = 0.5 * (N[0, 2] - N[2, 0])
    a2 = 0.5 * (N[1, 0] - N[0, 1])
    if theta >= _PREC:
        t = theta / math.sin(theta)
    else:
        n2 = a0 * a0 + a1 * a1 + a2 * a2
        t = 1.0 + n2 / 6.0 + n2 * n2 * 3.0 / 40.0
    out[0], out[1], out[2] = t * a0, t * a1, t * a2


@njit
def pid_command(rec, kp, ki, kd, windup, integral, err, derr, n, dt, out):
    """Write P e + D e_dot (+ I integral, clamped) into out, as PIDController.compute_command."""
    any_i = False
    for i in range(n):
        if rec[ki + i] != 0.0:
            any_i = True
    for i in range(n):
        out[i] = rec[kp + i] * err[i] + rec[kd + i] * derr[i]
    if dt > 0.0 and any_i:
        for i in range(n):
            rec[integral + i] += err[i] * dt
            gi = rec[ki + i]
            term = gi * rec[integral + i]
            w = rec[windup + i]
            term = min(w, max(-w, term))
            if gi != 0.0:
                rec[integral + i] = term / gi
            out[i] += term


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


@njit
def joint_rows(rec, n, q, v, f, dt, tmp):
    """One joint acceleration task: f = qdd_ref + PID(q_ref - q, qd_ref - qd), errors into rec."""
    qe = rec[J_Q_ERR * n: (J_Q_ERR + 1) * n]
    qde = rec[J_QD_ERR * n: (J_QD_ERR + 1) * n]
    for i in range(n):
        qe[i] = rec[J_Q_REF * n + i] - q[i]
        qde[i] = rec[J_QD_REF * n + i] - v[i]
    pid_command(
        rec, J_KP * n, J_KI * n, J_KD * n, J_WINDUP * n, J_INTEGRAL * n, qe, qde, n, dt, tmp
    )
    for i in range(n):
        f[i] = rec[J_QDD_REF * n + i] + tmp[i]


@njit
def viable_upper(room, v, acc, dt, h, one_step, margin=True):
    """Return the largest admissible acceleration towards one limit (as ViableBound.upper)."""
    if room >= _FAR:
        return np.inf
    R = room
    dt2 = dt * dt
    a = R - v * dt
    b = 2.0 * dt * v + acc * dt2
    c = v * v - 2.0 * acc * a
    disc = b * b - 4.0 * dt2 * c
    stop = v * (-1.0 / dt)
    if disc < 0.0:
        d = stop
    else:
        d = max((math.sqrt(disc) - b) * (0.5 / dt2), stop)
    e = (R - h * v) * (2.0 / (h * h))
    d = min(d, e)
    spare = acc * R - 0.5 * v * v  # A s: the braking margin (ViableBound.upper's f)
    if margin and v > 0.0 and spare > 0.0:  # it shrinks at most with the time constant h / 2
        d = min(d, spare / (MARGIN_SHARE * h * v) - acc)
    d = max(d, -acc)
    if one_step:
        return min(a * (2.0 / dt2), d)
    return d


@njit
def position_box(q, v, lo, hi, acc, dt, horizon, lb, ub):
    """Viable joint position limits as bounds on the joint accelerations (both sides)."""
    h = max(horizon, dt)
    for i in range(q.shape[0]):
        ub[i] = viable_upper(min(hi[i] - q[i], _FAR), v[i], acc[i], dt, h, True)
        lb[i] = -viable_upper(min(q[i] - lo[i], _FAR), -v[i], acc[i], dt, h, True)


@njit
def com_rows(rec, com, vcom, Jcom, oMi, vj, aj, body, E, f, row, dt, tmp):
    """
    One CoM task: E[row:row+3] = Jcom, f = a_ref + PID(p_ref - p, v_ref - v) - bias.

    The bias (the CoM's acceleration at zero joint acceleration) from every body's drift in
    Data (``aj``, left by computeAllTerms): sum m (R (a + dw x c + w x (v + w x c))) / m_total,
    with ``body[j]`` = [mass, lever] of joint j's body and ``body[0, 0]`` the total mass.
    """
    b0 = b1 = b2 = 0.0
    for j in range(1, oMi.shape[0]):
        m = body[j, 0]
        if m == 0.0:
            continue
        cx, cy, cz = body[j, 1], body[j, 2], body[j, 3]
        vx, vy, vz, wx, wy, wz = vj[j, 0], vj[j, 1], vj[j, 2], vj[j, 3], vj[j, 4], vj[j, 5]
        ax, ay, az, dx, dy, dz = aj[j, 0], aj[j, 1], aj[j, 2], aj[j, 3], aj[j, 4], aj[j, 5]
        # velocity of the body's CoM (joint axes), then its classical acceleration
        ux, uy, uz = vx + wy * cz - wz * cy, vy + wz * cx - wx * cz, vz + wx * cy - wy * cx
        px = ax + dy * cz - dz * cy + wy * uz - wz * uy
        py = ay + dz * cx - dx * cz + wz * ux - wx * uz
        pz = az + dx * cy - dy * cx + wx * uy - wy * ux
        # rotate into the world: R is stored column-major in oMi[j, 0:9]
        b0 += m * (oMi[j, 0] * px + oMi[j, 3] * py + oMi[j, 6] * pz)
        b1 += m * (oMi[j, 1] * px + oMi[j, 4] * py + oMi[j, 7] * pz)
        b2 += m * (oMi[j, 2] * px + oMi[j, 5] * py + oMi[j, 8] * pz)
    total = body[0, 0]
    err = rec[C_ERR * 3: C_ERR * 3 + 3]
    derr = tmp[0:3]
    for i in range(3):
        err[i] = rec[C_P_REF * 3 + i] - com[i]
        derr[i] = rec[C_V_REF * 3 + i] - vcom[i]
    cmd = tmp[3:6]
    pid_command(rec, C_KP * 3, C_KI * 3, C_KD * 3, C_WINDUP * 3, C_INTEGRAL * 3, err, derr, 3, dt,
                cmd)
    bias = (b0 / total, b1 / total, b2 / total)
    for i in range(3):
        f[row + i] = (rec[C_A_REF * 3 + i] + cmd[i]) - bias[i]
        for c in range(Jcom.shape[1]):
            E[row + i, c] = Jcom[i, c]


@njit
def momentum_rows(rec, Ag, h, drift, inv_m, E, f, row, dt, tmp):
    """
    One momentum task: E[row:row+6] = A_g / m, f = (h_dot_ref + PI(h_ref - h) - A_g_dot nu) / m.

    h = A_g nu, A_g and the drift A_g_dot nu: the robot's CentroidalMomentum terms of this state
    (Pinocchio's dccrba; the reference path's very numbers). MomentumTask's maths.
    """
    err = rec[M_ERR * 6: M_ERR * 6 + 6]
    derr, cmd = tmp[0:6], tmp[6:12]
    for i in range(6):
        err[i] = rec[M_H_REF * 6 + i] - h[i]
        derr[i] = 0.0  # (no derivative term: the momentum's rate is not measured)
    pid_command(rec, M_KP * 6, M_KI * 6, M_KD * 6, M_WINDUP * 6, M_INTEGRAL * 6, err, derr, 6,
                dt, cmd)
    for i in range(6):
        f[row + i] = ((rec[M_HD_REF * 6 + i] + cmd[i]) - drift[i]) * inv_m
        for c in range(Ag.shape[1]):
            E[row + i, c] = Ag[i, c] * inv_m
