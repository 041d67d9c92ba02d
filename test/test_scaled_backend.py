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
"""ScaledBackend: the solver works on x / d and returns the solution of the unscaled problem."""

import numpy as np
from orca_ros.optim.solvers import make_backend, QPSolver, ReturnCode, ScaledBackend
import pytest


def _problem(rng, nx=12, ne=3, ni=6):
    """Make a strictly convex QP whose variables' sizes span four orders of magnitude."""
    d = 10.0 ** rng.uniform(-1, 3, nx)  # physical size of each variable
    Ls = rng.normal(size=(nx, nx))
    Hs = Ls @ Ls.T + nx * np.eye(nx)  # well conditioned in scaled units
    H = Hs / np.outer(d, d)
    g = rng.normal(size=nx) / d
    A = rng.normal(size=(ne, nx)) / d
    x_feas = rng.normal(size=nx) * d
    b = A @ x_feas
    C = rng.normal(size=(ni, nx)) / d
    y = C @ x_feas
    lo, up = y - rng.uniform(0.0, 1.0, ni), y + rng.uniform(0.0, 1.0, ni)
    lbox, ubox = x_feas - 0.5 * d, x_feas + 0.5 * d
    return d, (H, g, A, b, C, lo, up, lbox, ubox)


@pytest.mark.parametrize('solver', list(QPSolver))
def test_scaled_solution_is_the_problem_solution(solver):
    rng = np.random.default_rng(7)
    for _ in range(20):
        d, qp = _problem(rng)
        scaled = make_backend(solver, 12, 3, 6, scale=d)
        assert isinstance(scaled, ScaledBackend)
        assert scaled.solve(*qp) is ReturnCode.SUCCESS
        x = scaled.x
        H, g, A, b, C, lo, up, lbox, ubox = qp
        # the KKT conditions of the original problem, in its units: feasibility, and optimality
        # checked by comparing with DAQP's exact active-set solution of the scaled problem
        assert np.abs(A @ x - b).max() <= 1e-6 * np.abs(b).max()
        assert np.all(C @ x >= lo - 1e-6 * np.abs(lo).max())
        assert np.all(C @ x <= up + 1e-6 * np.abs(up).max())
        assert np.all(x >= lbox - 1e-6 * d) and np.all(x <= ubox + 1e-6 * d)
        ref = make_backend(QPSolver.DAQP, 12, 3, 6, scale=d)
        assert ref.solve(*qp) is ReturnCode.SUCCESS
        assert np.abs((x - ref.x) / d).max() <= 1e-6
        plain = make_backend(QPSolver.DAQP, 12, 3, 6)  # the same problem, unscaled
        assert plain.solve(*qp) is ReturnCode.SUCCESS
        assert np.abs((x - plain.x) / d).max() <= 1e-6


def test_unit_scale_gives_the_plain_back_end():
    assert not isinstance(make_backend(QPSolver.DAQP, 4, 1, 1, scale=np.ones(4)), ScaledBackend)
    assert not isinstance(make_backend(QPSolver.DAQP, 4, 1, 1), ScaledBackend)
