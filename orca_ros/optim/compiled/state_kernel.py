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
inputs, ``set_configuration(q, v)`` and a fixed base's ``set_robot_state(q, v)``, of contiguous
float64 arrays of the right sizes on a robot without continuous joints, are checked (finite; the
base quaternion's norm) and written in one call (~1 us instead of ~3-4 us of numpy calls). A
state it refuses, and every other input, takes the Python path, which names the fault.
"""

from __future__ import annotations

import math

import numpy as np

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


@njit
def configuration(q, v, q_pin, v_pin, q_out, v_out, nb, tol):
    """Take Pinocchio's (q, v); the joints' part into (q_out, v_out). 0: taken, 1: refused."""
    if not _finite(q, v):
        return _REFUSED
    n = 1.0
    if nb:
        n = math.sqrt(q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6])
        if not abs(n - 1.0) <= tol:
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
def joint_state(q, v, q_pin, v_pin, q_out, v_out):
    """Take a fixed base's joint (q, v). 0: taken, 1: refused."""
    if not _finite(q, v):
        return _REFUSED
    for k in range(q.shape[0]):
        q_out[k] = q[k]
        v_out[k] = v[k]
        q_pin[k] = q[k]
        v_pin[k] = v[k]
    return _OK


def _fits(a, n) -> bool:
    # exactly the type the kernels' entry points were compiled for (see utils.jit.entry)
    return (type(a) is np.ndarray and a.dtype == np.float64 and a.shape == (n,)
            and a.flags.c_contiguous and a.flags.aligned)


class StateKernel:
    """The robot's fast state input (see the module); compiled or loaded when made."""

    def __init__(self, robot, tol: float):
        self.tol = tol
        r = robot
        q, v = r._q_pin.copy(), r._v_pin.copy()
        self._configuration = entry(
            configuration, q, v, q.copy(), v.copy(), r._q.copy(), r._v.copy(), r.nbase, tol
        )
        self._joint_state = entry(joint_state, r._q.copy(), r._v.copy(), q, v, r._q, r._v)

    def configuration(self, robot, q, v) -> bool:
        """Return True when the state was taken; False: the Python path takes (or refuses) it."""
        r = robot
        if not (r._q_simple and _fits(q, r.model.nq) and _fits(v, r.model.nv)):
            return False
        return self._configuration(q, v, r._q_pin, r._v_pin, r._q, r._v, r.nbase, self.tol) == _OK

    def joint_state(self, robot, q, v) -> bool:
        """Return True when a fixed base's (q, v) was taken; False: the Python path's."""
        r = robot
        if r.floating_base or not (r._q_simple and _fits(q, r.ndof) and _fits(v, r.ndof)):
            return False
        return self._joint_state(q, v, r._q_pin, r._v_pin, r._q, r._v) == _OK
