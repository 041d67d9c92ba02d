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
Kinematics of one frame relative to another, from world-frame quantities.

All inputs are "world aligned": position p, rotation R, Jacobian J = [J_lin; J_ang] mapping
generalized velocities to (velocity of the frame origin, angular velocity) in world axes, bias
acceleration a = J_dot * nu (classical: linear part is the second derivative of the origin
position), and velocity.

For a tip frame f seen from a reference frame b, with r = p_f - p_b, the relative position R_b^T r
has
    velocity       R_b^T (r_dot - w_b x r)
    acceleration   R_b^T (r_ddot - dw_b x r - 2 w_b x r_dot + w_b x (w_b x r))
and the relative angular velocity R_b^T (w_f - w_b) has derivative R_b^T (dw_f - dw_b - w_b x (w_f
- w_b)). The terms linear in the generalized accelerations form the relative Jacobian; the rest is
the bias.
"""

from __future__ import annotations

import numpy as np


def skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def relative_pose(Tb: np.ndarray, Tf: np.ndarray) -> np.ndarray:
    """b_H_f from world_H_b and world_H_f."""
    out = np.eye(4)
    Rbt = Tb[:3, :3].T
    out[:3, :3] = Rbt @ Tf[:3, :3]
    out[:3, 3] = Rbt @ (Tf[:3, 3] - Tb[:3, 3])
    return out


def relative_jacobian(Tb, Jb, Tf, Jf) -> np.ndarray:
    Rbt = Tb[:3, :3].T
    r = Tf[:3, 3] - Tb[:3, 3]
    J = np.empty_like(Jf)
    J[:3] = Rbt @ (Jf[:3] - Jb[:3] + skew(r) @ Jb[3:])
    J[3:] = Rbt @ (Jf[3:] - Jb[3:])
    return J


def relative_velocity(Tb, vb, Tf, vf) -> np.ndarray:
    Rbt = Tb[:3, :3].T
    r = Tf[:3, 3] - Tb[:3, 3]
    out = np.empty(6)
    out[:3] = Rbt @ (vf[:3] - vb[:3] - np.cross(vb[3:], r))
    out[3:] = Rbt @ (vf[3:] - vb[3:])
    return out


def relative_bias_acceleration(Tb, vb, ab, Tf, vf, af) -> np.ndarray:
    Rbt = Tb[:3, :3].T
    r = Tf[:3, 3] - Tb[:3, 3]
    rdot = vf[:3] - vb[:3]
    wb = vb[3:]
    out = np.empty(6)
    out[:3] = Rbt @ (
        af[:3]
        - ab[:3]
        + np.cross(r, ab[3:])
        - 2.0 * np.cross(wb, rdot)
        + np.cross(wb, np.cross(wb, r))
    )
    out[3:] = Rbt @ (af[3:] - ab[3:] - np.cross(wb, vf[3:] - wb))
    return out
