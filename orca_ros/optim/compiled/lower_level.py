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
A priority level's problem by kernel: what ``LowerLevelProblem`` lock, build and solve set up.

For a level below the first (:mod:`orca_ros.optim.lower_level_problem`), solved for its step
z = x - x_ref from the solution x_ref of the level above, in DAQP's stacked layout: its Hessian and
gradient from its rows of the plan (written by the cycle's kernel), the lock rows (the locked
tasks' selected rows, equalities z-wise), the constraints' rows and their bounds relaxed around
x_ref, the temporal damping. :func:`prepare` writes all of it in place; DAQP's C solve by kernel
(:mod:`.direct_daqp`) then writes x = x_ref + z into the level's own x. A GENERALIZED level
(:mod:`orca_ros.optim.generalized`) has the same cost as its weighted reference: once that is
solved, :func:`bands` turns its lock rows into bands and writes the banded form.

Tables (made by :class:`~orca_ros.optim.compiled.cascade.CompiledCascade` at configuration):
``cdiag`` the diagonal tasks of the level's cost (rows of the plan's diagonal table), ``own`` and
``own_dg`` the level's own tasks (dense, diagonal: where their effective weights are), ``locks``
one row per locked task (:data:`L_KIND` 0 dense rows of the plan, 1 diagonal; its first row, rows,
first column, where its effective weight is).
"""

from __future__ import annotations

import math

from numba.experimental import structref

from ..solvers import daqp_kernel as K
from ..solvers.daqp_c import UPDATE_ALL
from ...utils.jit import njit
from ...utils.struct_type import StructType

L_KIND, L_ROW, L_N, L_COL, L_W = range(5)
#: prepare's outcomes; prepare_and_solve's flag for them, when it did not solve: PREPARED - outcome
READY, NON_FINITE, NOTHING_TO_DO = 0, 1, 2
PREPARED = -200
#: room left to the step (LowerLevelProblem's _ROOM_TOL)
ROOM_TOL = 1e-6
#: LowerLevelProblem's
LOCK_RANK_TOL = 1e-6

FIELDS = (
    # the plan's arrays (rows, weights, diagonal tasks, constraints)
    'E', 'f', 'w', 'sel', 'ew', 'nw', 'dg_sel', 'dg_ws', 'dg_wsf', 'dg_ew', 'dg_nw', 'dg_tab',
    'pM', 'plo', 'phi',
    # the level's tables and cost rows [r0, r1)
    'cdiag', 'own', 'own_dg', 'locks', 'r0', 'r1',
    # GENERALIZED: the tasks of the levels above (dense, diagonal), whose costs the level holds
    'up', 'up_dg',
    # the level's problem (LowerLevelProblem's arrays): H, g, M = [A_eq; locks; C], b, lo, hi
    'H', 'g', 'M', 'b', 'lo', 'hi', 'x_above', 'x_ref', 'x', 'prev_ok', 'damp_w', 'mu',
    # what the solver reads: the damped Hessian and the gradient at x_ref
    'Hd', 'g2', 'nc', 'ni', 'nx',
    # GENERALIZED: the band share (1 - alpha)^2 per lock row, the weighted reference's solution,
    # the bands, and the banded form in DAQP's layout: M = [A_eq; C; locks],
    # lo = [lbox'; 0; l'; -band], hi
    'keep', 'ref_x', 'band', 'Mb', 'lob', 'hib',
)


@structref.register
class LevelStateType(StructType):
    """Its fields' types: see struct_type."""


class LevelState(structref.StructRefProxy):
    """The arrays of one strict level's problem by kernel (fields: :data:`FIELDS`)."""


structref.define_proxy(LevelState, LevelStateType, list(FIELDS))


@njit
def make_level_state(*fields):
    """Make a LevelState in compiled code: cached on disk, unlike the proxy's own constructor."""
    return LevelState(*fields)


@njit
def _relax(lo, hi, value, out_lo, out_hi, k):
    """Bounds on the step: the room left around ``value``, less ROOM_TOL, never excluding 0."""
    a = lo - value + ROOM_TOL
    b = hi - value - ROOM_TOL
    out_lo[k] = a if a < 0.0 else 0.0
    out_hi[k] = b if b > 0.0 else 0.0


@njit
def orthonormalise_locks(M, b, x_above, r0, r1, nx):
    """Rows [r0, r1) of M orthonormal, b their values at x_above (orthonormalise_locks')."""
    top = 0.0
    for r in range(r0, r1):
        n = 0.0
        for a in range(nx):
            n += M[r, a] * M[r, a]
        top = max(top, n)
    tol = LOCK_RANK_TOL * math.sqrt(top)
    for r in range(r0, r1):
        for q in range(r0, r):
            c = 0.0
            for a in range(nx):
                c += M[r, a] * M[q, a]
            if c != 0.0:
                for a in range(nx):
                    M[r, a] -= c * M[q, a]
        n = 0.0
        for a in range(nx):
            n += M[r, a] * M[r, a]
        n = math.sqrt(n)
        v = 0.0
        for a in range(nx):
            M[r, a] = M[r, a] / n if n > tol and n > 0.0 else 0.0
            v += M[r, a] * x_above[a]
        b[r] = v


@njit
def prepare(s, strict):
    """
    Write the level's problem for this cycle; return READY, NON_FINITE or NOTHING_TO_DO.

    ``strict``: with the lock rows of the strict form (orthonormal: :func:`strict_form`);
    False (a GENERALIZED level) leaves them as the tasks give them, for :func:`bands`.
    """
    ew, dg_ew = s.ew, s.dg_ew
    # weighted: some own task in the cost; weight: their weights, ramps left out, and the upper
    # tasks' under GENERALIZED (PriorityLevels.damping_scale: mu[0] and mu[1] its shares)
    weighted, weight, upper = False, 0.0, 0.0
    for k in range(s.own.shape[0]):
        weighted = weighted or ew[s.own[k]] > 0.0
        weight += s.nw[s.own[k]]
    for k in range(s.own_dg.shape[0]):
        weighted = weighted or dg_ew[s.own_dg[k]] > 0.0
        weight += s.dg_nw[s.own_dg[k]]
    for k in range(s.up.shape[0]):
        upper += s.nw[s.up[k]]
    for k in range(s.up_dg.shape[0]):
        upper += s.dg_nw[s.up_dg[k]]
    if not weighted:
        return NOTHING_TO_DO  # the solution above stands
    nx, nc, ni = s.nx, s.nc, s.ni
    E, f, w, H, g = s.E, s.f, s.w, s.H, s.g
    # cost: H = E^T W E + diag(ws), g = -E^T W f - wsf over the level's rows
    H[:, :] = 0.0
    g[:] = 0.0
    for r in range(s.r0, s.r1):
        wr = w[r]
        if wr == 0.0:
            continue
        for a in range(nx):
            wa = wr * E[r, a]
            if wa == 0.0:
                continue
            g[a] -= wa * f[r]
            for b in range(nx):
                H[a, b] += wa * E[r, b]
    for k in range(s.cdiag.shape[0]):
        d = s.cdiag[k]
        r0, n, c0 = s.dg_tab[d, 0], s.dg_tab[d, 1], s.dg_tab[d, 2]
        for i in range(n):
            H[c0 + i, c0 + i] += s.dg_ws[r0 + i]
            g[c0 + i] -= s.dg_wsf[r0 + i]
    total = 0.0
    for a in range(nx):
        total += g[a]
        for b in range(nx):
            total += H[a, b]
    if not math.isfinite(total):
        return NON_FINITE
    # equalities: the constraints' as they are (x_above meets them), then the locks
    M, b, pM, plo, x_above, x_ref, Mb = s.M, s.b, s.pM, s.plo, s.x_above, s.x_ref, s.Mb
    for a in range(nx):
        x_ref[a] = x_above[a]
    for i in range(nc):
        for a in range(nx):
            M[i, a] = pM[i, a]
        b[i] = plo[nx + i]
    row = nc
    for k in range(s.locks.shape[0]):
        kind, r0, n, c0 = s.locks[k, L_KIND], s.locks[k, L_ROW], s.locks[k, L_N], s.locks[k, L_COL]
        on = (ew[s.locks[k, L_W]] if kind == 0 else dg_ew[s.locks[k, L_W]]) > 0.0
        for i in range(n):
            v = 0.0
            for a in range(nx):
                if not on:
                    e = 0.0
                elif kind == 0:
                    e = E[r0 + i, a] * s.sel[r0 + i]
                else:
                    e = s.dg_sel[r0 + i] if a == c0 + i else 0.0
                M[row + i, a] = e
                Mb[nc + ni + row - nc + i, a] = e  # as they are, for the bands
                v += e * x_above[a]
            b[row + i] = v
        row += n
    ne = row
    if strict:  # (strict_form's)
        orthonormalise_locks(M, b, x_above, nc, ne, nx)
    # inequalities and bounds: relaxed around x_ref
    lo, hi, phi = s.lo, s.hi, s.phi
    for i in range(ni):
        v = 0.0
        for a in range(nx):
            c = pM[nc + i, a]
            M[ne + i, a] = c
            v += c * x_ref[a]
        _relax(plo[nx + nc + i], phi[nx + nc + i], v, lo, hi, nx + ne + i)
    for i in range(ne):
        lo[nx + i] = 0.0
        hi[nx + i] = 0.0
    for a in range(nx):
        _relax(plo[a], phi[a], x_ref[a], lo, hi, a)
    # the solver's Hessian and gradient at x_ref, damped towards the last solution (or x_ref)
    Hd, g2, mu = s.Hd, s.g2, s.mu[0] * weight + s.mu[1] * upper
    prev = s.x if s.prev_ok[0] else x_ref
    for a in range(nx):
        mw = mu * s.damp_w[a] if mu > 0.0 else 0.0
        v = g[a] - mw * prev[a]
        for c in range(nx):
            h = H[a, c] + (mw if a == c else 0.0)
            Hd[a, c] = h
            v += h * x_ref[c]
        g2[a] = v
    return READY


@njit
def strict_form(s):
    """Make the lock rows the strict form's (LowerLevelProblem's): orthonormal, their values."""
    orthonormalise_locks(s.M, s.b, s.x_above, s.nc, s.nc + s.band.shape[0], s.nx)


@njit
def prepare_and_solve(s, solve_state, mask, deadline, most, least, timing, clock):
    """
    Prepare the level, then solve it as :func:`.daqp_kernel.timed_solve` does (one call).

    Returns its (flag, iterations, cap, nanoseconds); when not solved, (PREPARED - prepare's
    outcome, 0, 0, 0): always with ``mask`` < 0 (prepare only, before a cold set-up).
    """
    ready = prepare(s, True)
    if ready != READY or mask < 0:
        return PREPARED - ready, 0, 0, 0
    return K.timed_solve(solve_state, mask, deadline, most, least, timing, clock)


@njit
def _orthonormal_rows(M, r0, r1, nx, kept):
    """
    Rows [r0, r1) of M orthonormal in place, as ``orthonormalise_locks``' (the reference path's).

    Modified Gram-Schmidt in row order against the rows kept so far; a row below LOCK_RANK_TOL
    of the largest becomes zero. Rows that are zero (the unselected components' rows: half of a
    Cartesian position task's) are passed over, not projected: the same rows, less work.
    ``kept``: a scratch of r1 - r0 entries (1.0 where a row was kept).
    """
    top = 0.0
    for r in range(r0, r1):
        n = 0.0
        for a in range(nx):
            n += M[r, a] * M[r, a]
        top = max(top, n)
        kept[r - r0] = 0.0
    tol = LOCK_RANK_TOL * math.sqrt(top)
    for r in range(r0, r1):
        n = 0.0
        for a in range(nx):
            n += M[r, a] * M[r, a]
        if n == 0.0:
            continue
        for q in range(r0, r):
            if kept[q - r0] == 0.0:
                continue
            c = 0.0
            for a in range(nx):
                c += M[r, a] * M[q, a]
            for a in range(nx):
                M[r, a] -= c * M[q, a]
        n = 0.0
        for a in range(nx):
            n += M[r, a] * M[r, a]
        n = math.sqrt(n)
        if n > tol and n > 0.0:
            for a in range(nx):
                M[r, a] /= n
            kept[r - r0] = 1.0
        else:
            for a in range(nx):
                M[r, a] = 0.0


@njit
def bands(s):
    """
    Bands of the lock rows from the reference's solution; the banded form when one is open.

    The lock rows made orthonormal in Mb (Gram-Schmidt in row order, as the strict form's:
    ``GeneralizedPriorities.bands``), band = (1 - alpha)^2 |row . (x_w - x_above)| (a
    switched-off task's rows are zero); returns how many bands are open (0: the strict form
    stands, as for the reference path's band None).
    """
    nx, nc, ni = s.nx, s.nc, s.ni
    x_above, ref_x, keep, band, Mb = s.x_above, s.ref_x, s.keep, s.band, s.Mb
    nl = band.shape[0]
    ne = nc + nl
    _orthonormal_rows(Mb, nc + ni, nc + ni + nl, nx, band)  # (band: its scratch, then below)
    n_open = 0
    for j in range(nl):
        v = 0.0
        for a in range(nx):
            v += Mb[nc + ni + j, a] * (ref_x[a] - x_above[a])
        band[j] = keep[j] * abs(v)
        if band[j] > 0.0:
            n_open += 1
    if n_open == 0:
        return 0
    M, lob, hib, lo, hi = s.M, s.lob, s.hib, s.lo, s.hi
    for i in range(nc):
        for a in range(nx):
            Mb[i, a] = M[i, a]
        lob[nx + i] = 0.0
        hib[nx + i] = 0.0
    for i in range(ni):
        for a in range(nx):
            Mb[nc + i, a] = M[ne + i, a]
        lob[nx + nc + i] = lo[nx + ne + i]
        hib[nx + nc + i] = hi[nx + ne + i]
    for j in range(nl):  # (Mb's lock rows: written by prepare, made orthonormal above)
        lob[nx + nc + ni + j] = -band[j]
        hib[nx + nc + ni + j] = band[j]
    for a in range(nx):
        lob[a] = lo[a]
        hib[a] = hi[a]
    return n_open


@njit
def weighted(s):
    """Whether every priority over the level is 0 (every band share 1)."""
    for j in range(s.keep.shape[0]):
        if s.keep[j] != 1.0:
            return False
    return True


#: prepare_and_solve_generalized's stages: not prepared, the reference not solved, the banded
#: form solved, the strict form solved (no band open)
S_PREPARED, S_REFERENCE, S_BANDED, S_STRICT = range(4)


@njit
def prepare_and_solve_generalized(s, ref, banded, strict, deadline, most, least, timing,
                                  clock):
    """
    Prepare a GENERALIZED level, solve its reference, then its banded (or strict) form.

    One call when every solve is warm, both solves capped by the reference's time model
    ``timing`` (:func:`.daqp_kernel.budgeted`), which takes their time and iterations when
    the last succeeds. Returns (flag, the reference's iterations, the last solve's
    iterations, stage, cap, nanoseconds): S_PREPARED with PREPARED - prepare's outcome when
    it is not ready; S_REFERENCE with the reference's flag when it did not solve (0: DAQP not
    set up); S_BANDED or S_STRICT with that solve's flag (0: not set up), the reference solved.
    The lock rows of the level's M take the strict form only where it is solved or the cycle
    goes on in Python (a failure): after a banded solve they are the tasks' rows as they are
    (no rewrite of them at every cycle).
    """
    ready = prepare(s, False)
    if ready != READY:
        return PREPARED - ready, 0, 0, S_PREPARED, 0, 0
    cap, start = K.budgeted(timing, deadline, most, least, clock)
    flag, it_ref = K.solve(ref, UPDATE_ALL, cap)
    stage, it = S_REFERENCE, 0
    if flag > 0:
        if bands(s) > 0:
            stage = S_BANDED
            if weighted(s):  # the reference is the solution (GeneralizedPriorities.bands)
                for a in range(s.nx):
                    s.x[a] = s.ref_x[a]
            else:
                flag, it = K.solve(banded, UPDATE_ALL, cap)
        else:
            stage = S_STRICT
            strict_form(s)
            flag, it = K.solve(strict, UPDATE_ALL, cap)
    if flag <= 0 and stage != S_STRICT:  # the strict form, for the Python that takes over
        strict_form(s)
    ns = K.monotonic_ns(clock) - start
    if flag > 0:
        K.record_time(timing, ns * 1e-9, it_ref + it)
    return flag, it_ref, it, stage, cap, ns
