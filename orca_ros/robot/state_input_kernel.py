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
The robot's state input by kernel: what :mod:`orca_ros.robot.state_input` does per cycle.

A compiled cycle gives its robot this kernel (``StateBuffers.state_kernel``): the common state
inputs on a robot without continuous joints, ``set_configuration(q, v)`` (float64 vectors of the
right sizes, any strides), a fixed base's ``set_robot_state(q, v)`` and a floating base's
``set_robot_state(world_H_base, q, base_twist, v, gravity)`` at the robot's gravity (contiguous
float64 arrays of the right sizes), are checked (finite; the base quaternion's norm, the base
rotation's orthonormality and sign) and written in one call
(instead of several numpy calls, each with its Python overhead). A state it refuses, and every
other input, takes the Python path, which names the fault.
"""

from __future__ import annotations

import math

from numba.experimental import structref
import numpy as np

from ..utils.jit import entry, njit
from ..utils.struct_type import StructType

_OK, _REFUSED = 0, 1


@njit
def _finite(a, b):
    s = 0.0
    for k in range(a.shape[0]):
        s += a[k]
    for k in range(b.shape[0]):
        s += b[k]
    if math.isfinite(s):
        return True
    for k in range(a.shape[0]):  # a sum of huge finite values may overflow: test exactly
        if not math.isfinite(a[k]):
            return False
    for k in range(b.shape[0]):
        if not math.isfinite(b[k]):
            return False
    return True


@structref.register
class RobotArraysType(StructType):
    """Its fields' types: see struct_type."""


class RobotArrays(structref.StructRefProxy):
    """
    The robot's state arrays the kernels write, and its sizes, in one structure.

    A call passes it as one argument (each array passed is unboxed at every call otherwise).
    """


_FIELDS = ('q_pin', 'v_pin', 'q_out', 'v_out', 'nb', 'tol')
structref.define_proxy(RobotArrays, RobotArraysType, list(_FIELDS))


@njit
def _robot_arrays(q_pin, v_pin, q_out, v_out, nb, tol):
    """Make the structure in compiled code: cached on disk, unlike the proxy's constructor."""
    return RobotArrays(q_pin, v_pin, q_out, v_out, nb, tol)


@njit
def configuration(q, v, r):
    """Take Pinocchio's (q, v) into the robot's arrays ``r``. 0: taken, 1: refused."""
    q_pin, v_pin, q_out, v_out, nb = r.q_pin, r.v_pin, r.q_out, r.v_out, r.nb
    if not _finite(q, v):
        return _REFUSED
    n = 1.0
    if nb:
        n = math.sqrt(q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6])
        if not abs(n - 1.0) <= r.tol:
            return _REFUSED
    for k in range(q.shape[0]):
        q_pin[k] = q[k]
    if nb:
        for k in range(3, 7):
            q_pin[k] /= n
    for k in range(v.shape[0]):
        v_pin[k] = v[k]
    first = q.shape[0] - q_out.shape[0]
    for k in range(q_out.shape[0]):
        q_out[k] = q_pin[first + k]
        v_out[k] = v[nb + k]
    return _OK


@njit
def joint_state(q, v, r):
    """Take a fixed base's joint (q, v) into the robot's arrays ``r``. 0: taken, 1: refused."""
    q_pin, v_pin, q_out, v_out = r.q_pin, r.v_pin, r.q_out, r.v_out
    if not _finite(q, v):
        return _REFUSED
    for k in range(q.shape[0]):
        q_out[k] = q[k]
        v_out[k] = v[k]
        q_pin[k] = q[k]
        v_pin[k] = v[k]
    return _OK


@njit
def _quaternion(R, q):
    """Write the unit quaternion of the rotation R into q[3:7] (x y z w; Eigen's conversion)."""
    t = R[0, 0] + R[1, 1] + R[2, 2]
    if t > 0.0:
        t = math.sqrt(t + 1.0)
        q[6] = 0.5 * t
        t = 0.5 / t
        q[3] = (R[2, 1] - R[1, 2]) * t
        q[4] = (R[0, 2] - R[2, 0]) * t
        q[5] = (R[1, 0] - R[0, 1]) * t
        return
    i = 0
    if R[1, 1] > R[0, 0]:
        i = 1
    if R[2, 2] > R[i, i]:
        i = 2
    j = (i + 1) % 3
    k = (j + 1) % 3
    t = math.sqrt(R[i, i] - R[j, j] - R[k, k] + 1.0)
    q[3 + i] = 0.5 * t
    t = 0.5 / t
    q[6] = (R[k, j] - R[j, k]) * t
    q[3 + j] = (R[j, i] + R[i, j]) * t
    q[3 + k] = (R[k, i] + R[i, k]) * t


@njit
def base_state(T, q, twist, v, r, world_H_base, base_twist):
    """
    Take a floating base's (world_H_base, q, base twist in world axes, v): 0 taken, 1 refused.

    As ``state_input.set_joint_and_base_state`` (without the gravity, which the caller took):
    every value finite, T's rotation block orthonormal to 1e-6 with determinant +1; Pinocchio's
    q (position, quaternion, joints) and v (the twist in base axes, R^T twist, then the joints).
    """
    q_pin, v_pin, q_out, v_out = r.q_pin, r.v_pin, r.q_out, r.v_out
    if not (_finite(q, v) and _finite(twist, T[3])):
        return _REFUSED
    for a in range(3):
        if not _finite(T[a], T[a]):
            return _REFUSED
    for a in range(3):  # R R^T - I, as rotations.is_rotation
        for b in range(3):
            e = T[a, 0] * T[b, 0] + T[a, 1] * T[b, 1] + T[a, 2] * T[b, 2]
            if not abs(e - (1.0 if a == b else 0.0)) <= 1e-6:
                return _REFUSED
    det = (T[0, 0] * (T[1, 1] * T[2, 2] - T[2, 1] * T[1, 2])
           - T[0, 1] * (T[1, 0] * T[2, 2] - T[2, 0] * T[1, 2])
           + T[0, 2] * (T[1, 0] * T[2, 1] - T[2, 0] * T[1, 1]))
    if not det > 0.0:
        return _REFUSED
    for a in range(4):
        for b in range(4):
            world_H_base[a, b] = T[a, b]
    for k in range(6):
        base_twist[k] = twist[k]
    for k in range(3):
        q_pin[k] = T[k, 3]
    _quaternion(T, q_pin)
    for c in range(3):  # R^T twist: world axes -> base axes
        v_pin[c] = twist[0] * T[0, c] + twist[1] * T[1, c] + twist[2] * T[2, c]
        v_pin[3 + c] = twist[3] * T[0, c] + twist[4] * T[1, c] + twist[5] * T[2, c]
    for k in range(q.shape[0]):
        q_out[k] = q[k]
        v_out[k] = v[k]
        q_pin[7 + k] = q[k]
        v_pin[6 + k] = v[k]
    return _OK


_F64 = np.dtype(np.float64)


def _fits(a, n) -> bool:
    # exactly the type the kernels' entry points were compiled for (see utils.jit.entry)
    if type(a) is not np.ndarray or a.shape != (n,):
        return False
    d, f = a.dtype, a.flags
    return (d is _F64 or d == _F64) and f.c_contiguous and f.aligned


def _strided(n: int) -> np.ndarray:
    """Return a strided float64 vector of n elements: numba's 'A' layout (read by its strides)."""
    return np.zeros((n, 2))[:, 0]


class StateKernel:
    """
    The robot's fast state input (see the module); compiled or loaded when made.

    Made for one Pinocchio model of the robot (its arrays and sizes): a new model comes with
    a new one (``StateBuffers.state_kernel`` is made anew with the model).

    ``RobotModel.set_configuration`` calls :attr:`take` inline (it runs every cycle): on
    ``(q, v)`` whose type is exactly ``np.ndarray``, whose dtype is float64 itself and whose
    shapes are :attr:`shapes`, with :attr:`arrays` (the robot's, in one structure) after them.
    The kernel reads them by their strides, so any such vector may come (a column, a slice); it
    refuses (1) what is not finite, or a base quaternion not of unit norm. ``shapes`` is None
    where the kernel does not apply (continuous joints: their cos, sin in q).
    """

    def __init__(self, robot, tol: float):
        r = robot
        self.buffers = b = r.buffers
        nq, nv, self.ndof, self.nb = r.model.nq, r.model.nv, r.ndof, r.nbase
        # no continuous joints (cos, sin in q_pin) and, for joint_state, a fixed base
        self.simple = b.q_simple
        self.fixed = b.q_simple and not r.floating_base
        self.shapes = ((nq,), (nv,)) if self.simple else None
        self.arrays = _robot_arrays(b.q_pin, b.v_pin, b.q, b.v, r.nbase, tol)
        self.take = entry(configuration, _strided(nq), _strided(nv), self.arrays)
        self._joint_state = entry(joint_state, b.q.copy(), b.v.copy(), self.arrays)
        self._base_state = None
        if self.simple and r.floating_base:
            self._base_state = entry(base_state, np.eye(4), b.q.copy(), np.zeros(6),
                                     b.v.copy(), self.arrays, b.world_H_base,
                                     b.base_twist_world)

    def joint_state(self, q, v) -> bool:
        """Take a fixed base's (q, v): True when taken; False: the Python path's."""
        n = self.ndof
        if not (self.fixed and _fits(q, n) and _fits(v, n)) or self._joint_state(
            q, v, self.arrays
        ) != _OK:
            return False
        b = self.buffers
        b.stamp += 1
        b.initialized = True
        return True

    def full_state(self, T, q, twist, v, g) -> bool:
        """
        Take a floating base's ``(world_H_base, q, base_twist, v, gravity)``: True when taken.

        Only with the gravity the robot has already (a new one is set on the Python path) and
        C-contiguous float64 arrays of the right shapes; False: the Python path's (which names a
        refused state).
        """
        b, n = self.buffers, self.ndof
        if self._base_state is None or not (
            _fits(q, n) and _fits(v, n) and _fits(twist, 6) and type(T) is np.ndarray
            and T.shape == (4, 4) and T.dtype == _F64 and T.flags.c_contiguous
            and type(g) is np.ndarray and g.shape == (3,)
        ):
            return False
        rg = b.gravity
        if not (g[0] == rg[0] and g[1] == rg[1] and g[2] == rg[2]):
            return False
        if self._base_state(T, q, twist, v, self.arrays, b.world_H_base,
                            b.base_twist_world) != _OK:
            return False
        b.base_from_q_pin = False
        b.stamp += 1
        b.initialized = True
        return True
