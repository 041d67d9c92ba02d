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
SurfaceContact.

One 6-D wrench per sole with the exact contact wrench cone of its corner pyramids.
"""

import numpy as np
import orca_ros as orca
from orca_ros.constraint import contact_wrench_cone
import pytest
from scipy.optimize import linprog

CORNERS = np.array(
    [[0.1, 0.065, 0.0], [0.1, -0.065, 0.0], [-0.1, -0.065, 0.0], [-0.1, 0.065, 0.0]]
)


def _decomposable(w, points, mu, n_edges=4):
    """Tell (LP) whether w is a non-negative combination of the corner pyramids' edge wrenches."""
    ang = 2.0 * np.pi * (np.arange(n_edges) + 0.5) / n_edges
    edges = np.column_stack((mu * np.cos(ang), mu * np.sin(ang), np.ones(n_edges)))
    G = np.array([np.concatenate((e, np.cross(p, e))) for p in points for e in edges]).T
    res = linprog(np.zeros(G.shape[1]), A_eq=G, b_eq=w, bounds=(0, None), method='highs')
    return res.status == 0


def test_wrench_cone_is_exactly_the_corner_pyramids():
    F = contact_wrench_cone(CORNERS, 0.3)
    assert F.shape == (16, 6)  # a rectangle with axis-aligned 4-face pyramids: 16 faces
    rng = np.random.default_rng(0)
    inside = outside = 0
    for _ in range(300):
        w = rng.normal(size=6) * [30, 30, 0, 5, 5, 3]
        w[2] = 100.0
        in_cone = bool(np.all(F @ w <= 1e-9))
        assert in_cone == _decomposable(w, CORNERS, 0.3)
        inside += in_cone
        outside += not in_cone
    assert inside > 20 and outside > 20


@pytest.mark.parametrize('solver', ['daqp', 'proxqp', 'osqp'])
def test_talos_on_two_soles_has_full_rank_equalities(solver, talos_standing):
    """
    Talos (example-robot-data, 38 DoF) on both soles.

    6 + 2 x 6 equality rows of full rank (as 8 corner point contacts they were 30 rows of rank 18,
    and ProxQP called the problem infeasible).
    """
    robot, _ = talos_standing()
    c = orca.Controller('c', robot, solver=solver)
    soles = [
        c.add_constraint(orca.SurfaceContact(f, f, CORNERS, friction_coefficient=0.3))
        for f in ('leg_left_sole_fix_joint', 'leg_right_sole_fix_joint')
    ]
    com = c.add_task(orca.CoMTask, 'com')
    com.set_desired(robot.get_center_of_mass() + [0.0, 0.02, 0.0])
    post = c.add_task(orca.JointAccelerationTask, 'posture')
    post.set_weight(1e-3)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 0.001), c.get_return_code()
    p = c.get_problem_at_level(0)
    assert p.n_eq == 18 and np.linalg.matrix_rank(p.A) == 18
    x = c.get_reduced_solution()
    W = np.array([s_.get_wrench(x) for s_ in soles])
    _, Jc, _, bias = robot.get_center_of_mass_terms()
    a_com = (
        Jc @ x[: robot.model.nv] + bias
    )  # Newton: the soles' forces carry the weight and the CoM's acceleration
    np.testing.assert_allclose(
        W[:, :3].sum(axis=0), robot.get_total_mass() * (a_com + [0, 0, 9.81]), atol=1e-4
    )
    F = contact_wrench_cone(CORNERS, 0.3)
    for s_, w in zip(soles, W):  # the soles are level: local axes = world axes
        R = robot.get_relative_transform('world', s_.frame)[:3, :3]
        w_local = np.concatenate((R.T @ w[:3], R.T @ w[3:]))
        # to the solver's accuracy on the problem's force scale (a sole may carry nothing)
        assert np.all(F @ w_local <= 1e-6 * np.abs(W).max())
