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
How a robot state enters a RobotModel.

Checked once, written into Pinocchio's configuration and velocity.

Two conventions are accepted:

* the controller's (``RobotModel.set_robot_state``): joint positions and velocities in the model's
  joint order, plus, for a floating base, the world pose of the base (4x4) and its twist in world
  axes, as odometry gives them;
* Pinocchio's (``RobotModel.set_configuration``): q (nq, base position + unit quaternion x y z w +
  joints) and v (nv, base twist in the base frame + joints), as Pinocchio and TSID users hold them.
  The world pose and twist of the base are then derived only when someone asks for them
  (:func:`sync_base`).

Every value is checked (shape, finite) before anything is written: a rejected state leaves the
previous one. These run every control cycle: each check costs one reduction, the slow exact test
runs only to name a fault. A compiled cycle gives the robot a kernel for the common inputs
(``robot.buffers.state_kernel``, :mod:`.state_input_kernel`): the same checks and
writes in one call; what it refuses comes here to be named.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ..math.rotations import is_rotation, quaternion_xyzw

_QUATERNION_TOL = 1e-3  # |norm - 1| accepted (and normalised away) in set_configuration


def checked(robot, x, shape, what) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.shape != shape:
        if a.size == int(np.prod(shape)) and len(shape) == 1:
            a = a.reshape(shape)
        else:
            raise ValueError(
                f"{what}: expected shape {shape} for robot '{robot.name}', got {a.shape}"
            )
    if not math.isfinite(
        a.sum()
    ):  # NaN and inf make the sum non-finite; so may huge finite values: test exactly
        with np.errstate(over='ignore'):
            if not np.isfinite(a).all():
                raise ValueError(f'{what}: contains NaN or infinite values: {a}')
    return a


def set_joint_and_base_state(robot, args) -> None:
    """``(q, v)`` for a fixed base, or ``(world_H_base, q, base_twist_world, v, gravity)``."""
    if len(args) == 2:
        if robot.floating_base:
            raise ValueError(
                'floating-base robot: use set_robot_state(world_H_base, q, base_twist, v, gravity)'
            )
        q, v = args
        T = None
    elif len(args) == 5:
        T, q, twist, v, g = args
        T = checked(robot, T, (4, 4), 'world_H_base')
        twist = checked(robot, twist, (6,), 'base twist')
        if not is_rotation(T[:3, :3]):
            raise ValueError('world_H_base rotation block is not a rotation matrix')
        g = checked(robot, g, (3,), 'gravity')
        if (g != robot.buffers.gravity).any():
            robot.set_gravity(g)
    else:
        raise TypeError(
            'set_robot_state takes (q, v) or (world_H_base, q, base_twist, v, gravity)'
        )
    q = checked(robot, q, (robot.ndof,), 'joint positions')
    v = checked(robot, v, (robot.ndof,), 'joint velocities')
    buf = robot.buffers
    buf.q[:] = q
    buf.v[:] = v
    q_pin, v_pin = buf.q_pin, buf.v_pin
    if buf.q_simple:
        q_pin[robot.model.nq - robot.ndof:] = q
    else:
        for k, (iq, nq) in enumerate(buf.q_map):
            if nq == 1:
                q_pin[iq] = q[k]
            else:
                q_pin[iq], q_pin[iq + 1] = math.cos(q[k]), math.sin(q[k])
    v_pin[robot.nbase:] = v
    if robot.floating_base and T is not None:
        buf.world_H_base[:] = T
        buf.base_twist_world[:] = twist
        buf.base_from_q_pin = False
        R = T[:3, :3]
        q_pin[:3] = T[:3, 3]
        q_pin[3:7] = quaternion_xyzw(R)
        np.dot(twist[:3], R, out=v_pin[:3])  # R^T twist: world axes -> base axes
        np.dot(twist[3:], R, out=v_pin[3:6])
    buf.stamp += 1
    buf.initialized = True


def set_configuration(robot, q, v) -> None:
    model = robot.model
    q = checked(robot, q, (model.nq,), 'configuration q')
    v = checked(robot, v, (model.nv,), 'velocity v')
    if robot.floating_base:
        n = math.sqrt(float(q[3:7] @ q[3:7]))
        if not abs(n - 1.0) <= _QUATERNION_TOL:
            raise ValueError(
                f'configuration q: base quaternion norm {n:.6f} is not 1 (x y z w order expected)'
            )
    buf = robot.buffers
    q_pin = buf.q_pin
    q_pin[:] = q
    if robot.floating_base:
        q_pin[3:7] /= n
        buf.base_from_q_pin = True
    buf.v_pin[:] = v
    nb, ndof = robot.nbase, robot.ndof
    if buf.q_simple:
        buf.q[:] = q_pin[model.nq - ndof:]
    else:
        for k, (iq, nq) in enumerate(buf.q_map):
            buf.q[k] = q_pin[iq] if nq == 1 else math.atan2(q_pin[iq + 1], q_pin[iq])
    buf.v[:] = v[nb:]
    buf.stamp += 1
    buf.initialized = True


def sync_base(robot) -> None:
    """World pose and world-axes twist of the base from q, v (after set_configuration)."""
    buf = robot.buffers
    if not buf.base_from_q_pin:
        return
    T = pin.XYZQUATToSE3(buf.q_pin[:7]).homogeneous
    R = T[:3, :3]
    buf.world_H_base[:] = T
    buf.base_twist_world[:3] = R @ buf.v_pin[:3]
    buf.base_twist_world[3:] = R @ buf.v_pin[3:6]
    buf.base_from_q_pin = False
