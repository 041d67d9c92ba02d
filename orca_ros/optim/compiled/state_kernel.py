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

A compiled cycle gives its robot this kernel (``RobotModel._state_kernel``): the common state
inputs on a robot without continuous joints, ``set_configuration(q, v)`` (float64 vectors of the
right sizes, any strides) and a fixed base's ``set_robot_state(q, v)`` (contiguous float64 arrays
of the right sizes), are checked (finite; the base quaternion's norm) and written in one call
(instead of several numpy calls, each with its Python overhead). A state it refuses, and every
other input, takes the Python path, which names the fault.
"""

from __future__ import annotations

import math

from numba.experimental import structref
import numpy as np

from .struct_type import StructType
from ...utils.jit import entry, njit

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
    a new one (``RobotModel._state_kernel`` is reset with the model).

    ``RobotModel.set_configuration`` calls :attr:`take` inline (it runs every cycle): on
    ``(q, v)`` whose type is exactly ``np.ndarray``, whose dtype is float64 itself and whose
    shapes are :attr:`shapes`, with :attr:`arrays` (the robot's, in one structure) after them.
    The kernel reads them by their strides, so any such vector may come (a column, a slice); it
    refuses (1) what is not finite, or a base quaternion not of unit norm. ``shapes`` is None
    where the kernel does not apply (continuous joints: their cos, sin in q).
    """

    def __init__(self, robot, tol: float):
        self.robot = r = robot
        nq, nv, self.ndof, self.nb = r.model.nq, r.model.nv, r.ndof, r.nbase
        # no continuous joints (cos, sin in q_pin) and, for joint_state, a fixed base
        self.simple = r._q_simple
        self.fixed = r._q_simple and not r.floating_base
        self.shapes = ((nq,), (nv,)) if self.simple else None
        self.arrays = _robot_arrays(r._q_pin, r._v_pin, r._q, r._v, r.nbase, tol)
        self.take = entry(configuration, _strided(nq), _strided(nv), self.arrays)
        self._joint_state = entry(joint_state, r._q.copy(), r._v.copy(), self.arrays)

    def joint_state(self, q, v) -> bool:
        """Take a fixed base's (q, v): True when taken; False: the Python path's."""
        n = self.ndof
        if not (self.fixed and _fits(q, n) and _fits(v, n)) or self._joint_state(
            q, v, self.arrays
        ) != _OK:
            return False
        r = self.robot
        r._stamp += 1
        r._initialized = True
        return True
