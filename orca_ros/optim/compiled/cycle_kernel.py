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
The cycle's kernels: every lowered object's rows, the plan's assembly, the solution's use.

:func:`run` fills and assembles, :func:`finish` writes the solution out; :func:`step` is both
with the first level's DAQP solve between them, one call for a whole one-level cycle.
"""

from __future__ import annotations

import math

from .assembly import assemble
from .fill import fill
from ..solvers.daqp_c import UPDATE_ALL
from ..solvers.daqp_kernel import timed_solve
from ...constraint.contact_kernel import contact_terms
from ...robot.terms_kernel import drift
from ...utils.jit import njit


@njit
def _drifts(ws):
    """Derive the joints' drifts after the two-pass Pinocchio pass, once (terms_kernel)."""
    if ws.derive[0]:
        drift(ws.oMi, ws.a_gf, ws.aj, ws.grav)
        ws.derive[0] = 0


@njit
def run(ws, dt):
    """
    Fill and assemble on the workspace ``ws``.

    Return flags: 1 soft boxes conflicted, 2 the first level's H or g is not finite.
    """
    _drifts(ws)
    fill(dt, ws)
    flags = assemble(ws)
    s = 0.0
    for a in range(ws.H.shape[0]):
        s += ws.g[a]
        for b in range(ws.H.shape[1]):
            s += ws.H[a, b]
    if not math.isfinite(s):
        flags |= 2
    return flags


@njit
def run_contacts(ws, dt):
    """Compute the contacts' kinematics, the torque map and the dynamics rows (first)."""
    _drifts(ws)
    return contact_terms(ws.oMi, ws.vj, ws.aj, ws.J, ws.ct_sup, ws.M_pin, ws.nle, ws.Wj, ws.T,
                         ws.t0, ws.M, ws.lo, ws.hi, ws.nx, ws.ct_tab, ws.ct_par, ws.ct_faces,
                         ws.dyn[0], ws.dyn[1], dt, ws.tmp)


@njit
def finish(ws, x, x_out, acc_out, tau, tau_cmd):
    """Copy the solution into the controller's arrays; torques tau = T x + t0, the command."""
    for a in range(x.shape[0]):
        x_out[a] = x[a]
    for a in range(acc_out.shape[0]):
        acc_out[a] = x[a]
    T, t0 = ws.T, ws.t0
    for i in range(tau.shape[0]):
        s = 0.0
        for a in range(x.shape[0]):
            s += T[i, a] * x[a]
        tau[i] = s + t0[i]
        tau_cmd[i] = tau[i]
    last, first = ws.ct_last, ws.ct_ws
    for c in range(ws.n_wrenches):
        for k in range(6):
            last[c, k] = x[first[c] + k]


#: step's exit flag when the first level's H or g is not finite (nothing solved)
NOT_BUILT = -200


@njit
def step(ws, s, dt, deadline, max_iterations, least, timing, clock, out, x_out, acc_out, tau,
         tau_cmd):
    """
    Fill, assemble, solve the first level warm (DAQP, ``s``), write the solution out (``out``).

    The solve as :func:`.daqp_kernel.timed_solve` with every part of the problem updated
    (capped and timed by the solver's time model ``timing`` and the clock at ``clock``); when
    it succeeded and with ``out`` (no level below), the solution written out (:func:`finish`).
    Returns (run's flags, DAQP's exit flag or NOT_BUILT, its iterations, the cap, the solve's
    nanoseconds).
    """
    flags = run(ws, dt)
    if flags & 2:
        return flags, NOT_BUILT, 0, 0, 0
    flag, iters, cap, ns = timed_solve(s, UPDATE_ALL, deadline, max_iterations, least, timing,
                                       clock)
    if flag == 1 and out:
        finish(ws, s.x, x_out, acc_out, tau, tau_cmd)
    return flags, flag, iters, cap, ns
