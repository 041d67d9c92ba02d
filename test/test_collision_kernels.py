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
Collision avoidance by kernel (constraint/collision_kernel.py) against its Python reference.

Two controllers of one configuration, compiled and not, fed the same states: the same pairs, rows,
bounds and torques, to 1e-9 relative. On random states (every pair's distance computed again: the
bodies jump) and along a closed-loop run, where the kernels skip pairs whose last distance, less
how far their bodies moved since, is still beyond reach (shown to happen). Obstacles of every kind:
fixed, moving with a velocity, fixed to a link.

Random states put bodies into each other too. A penetration's depth is EPA's, to its tolerance
(1e-6), and coal's distance objects start EPA from where their last call ended: the two paths,
which compute different sets of pairs per cycle, then differ by ~1e-7 in a depth. Such states are
compared to that tolerance; 500 states without are compared to 1e-9.

Distances apart from contact are GJK's, which stops within its tolerance of the distance,
started from each pair's last result on either path: they agree to that tolerance
(``_distance_slack``), and the kernels' placements of the geometries, from which coal computes
them, to rounding (``_check_placements``).
"""

import numpy as np
import orca_ros as orca
from orca_ros.robot.collision_geometry import GJK_TOLERANCE
import pinocchio as pin
import pytest

EPS = np.finfo(float).eps


def _gamma(n):
    """Higham's gamma_n = n u / (1 - n u), u = eps / 2: an n-term dot product's relative error."""
    return n * EPS / 2 / (1 - n * EPS / 2)


#: |kernel's oMg - oMi[joint] * placement| <= PLACEMENT_ROUNDING * |oMi[joint]| |placement|
#: (entrywise, 4x4 homogeneous). Both sides compose the same two placements: the kernel
#: (collision_screen_kernel._place) in its own order, Pinocchio's product
#: (updateGeometryPlacements') in Eigen's, maybe vectorised or fused (FMA). Each entry is a sum
#: of at most 4 products
#: (R_ij = sum_k R1_ik R2_kj; t_i = t1_i + sum_k R1_ik t2_k), within gamma_4 times the sum of
#: their magnitudes of the exact one in any order, fused or not: the two within 2 gamma_4 of each
#: other; gamma_5 >= gamma_4 (1 + u) also covers the rounding of the bound's own product.
PLACEMENT_ROUNDING = 2 * _gamma(5)

#: GJK's own arithmetic, per unit of the largest coordinate involved (``_distance_slack``): the
#: relative placement of the two bodies, their support points and the iterate are sums of at most 4
#: products of such coordinates (within gamma_4 of their magnitudes each), some 8 steps deep from
#: the placements to the distance, on each of the two paths. (1e-5 of the tolerance's share.)
DISTANCE_ROUNDING = 2 * 8 * _gamma(4)


def _pair(urdf, srdf, frame, floating):
    out = []
    for compiled in (True, False):
        robot = orca.RobotModel()
        robot.load_model_from_file(urdf, floating_base=floating)
        c = orca.Controller('c', robot, compiled=compiled)
        c.set_solver_budget(time_budget=10.0)  # the same solves on both paths (offline)
        ee = c.add_task(orca.CartesianTask, 'ee')
        ee.set_control_frame(frame)
        ee.servo_controller().pid().set_proportional_gain([100.0] * 6)
        ee.servo_controller().pid().set_derivative_gain([20.0] * 6)
        post = c.add_task(orca.JointAccelerationTask, 'posture')
        post.set_weight(1e-3)
        for kind, name in ((orca.JointTorqueLimitConstraint, 'torque'),
                           (orca.JointPositionLimitConstraint, 'position'),
                           (orca.JointVelocityLimitConstraint, 'velocity')):
            c.add_constraint(kind, name)
        col = c.add_constraint(orca.CollisionAvoidanceConstraint('collision', srdf=srdf))
        ball = np.eye(4)
        ball[:3, 3] = [0.45, 0.0, 0.45]
        col.add_obstacle('ball', 'sphere', [0.1], ball)
        col.add_obstacle('bar', 'capsule', [0.03, 0.4], ball)  # moves: see _move
        on_link = np.eye(4)
        on_link[:3, 3] = [0.0, 0.25, 0.1]
        col.add_obstacle('tool', 'box', [0.1, 0.05, 0.08], on_link, frame)
        c.activate_tasks_and_constraints()
        out.append((robot, c, ee, post, col))
    return out


def _move(col, t):
    """Move the bar across the workspace at 0.4 m/s, its pose stamped (it moves on between)."""
    T = np.eye(4)
    T[:3, 3] = [0.3, -0.4 + 0.4 * (t % 2.0), 0.3]
    col.move_obstacle('bar', T, velocity=[0.0, 0.4, 0.0], at=t)


def _check_placements(pair):
    """Check the kernels' placements of the geometries: Pinocchio's, to their rounding."""
    r1, k1 = pair[0][0], pair[0][4]
    gm, gd = k1.geometry.geom_model, k1.geometry.geom_data
    for g, obj in enumerate(gm.geometryObjects):
        A, B = r1.data.oMi[obj.parentJoint].homogeneous, obj.placement.homogeneous
        off = np.abs(gd.oMg[g].homogeneous - A @ B)
        assert np.all(off <= PLACEMENT_ROUNDING * (np.abs(A) @ np.abs(B))), (obj.name, off)


def _distance_slack(k1, k2, names, d):
    """
    Return how far the two paths' distances of the pair ``names`` may be apart, and its normals.

    Both paths' distances are coal's GJK (computeDistance), but neither on the same placements nor
    from the same start. GJK stops when its iterate's norm rl (the distance between the bodies'
    cores: d plus their inflation, the swept-sphere radius and a sphere's or capsule's radius,
    each within the body's bounding radius) is within GJK_TOLERANCE (1 + rl) of the best lower
    bound found (coal's default convergence criterion): a distance in [d*, d* + GJK_TOLERANCE
    (1 + rl)], d* the exact one. Pinocchio starts each pair's GJK from that pair's last result
    (enable_cached_gjk_guess), and the kernels skip far pairs: the two paths start a pair from
    different points and end at different points of that interval. Seen: 3.2e-12 apart on a
    2-core machine; 7.9e-11 (link1 and the tool) on this run started 1e-6 rad off, its
    placements 1.1e-16 apart, the reference once stopping 2.1e-11 above the distance GJK gives
    from a cold start at any tolerance from 1e-9 to 1e-13; at coal's default tolerance 1e-6, two
    starts 1.10e-6 apart at d = 0.107 (the bound: 1.13e-6 or more). Rounding (64 ulps of 1 m:
    1.4e-14) does not account for them.

    The placements differ by rounding (the kernels compose them, _check_placements; the two
    paths' Pinocchio passes differ): d* moves by no more than any point of either body does
    between the two placements (|dt| + |dR| times the body's reach from its origin). And GJK's
    own rounding: DISTANCE_ROUNDING times the largest coordinate.

    The normals: each path's iterate x lies in the bodies' Minkowski difference, whose point
    nearest the origin x* has |x - x*|^2 <= |x|^2 - |x*|^2 <= 2 rl s + s^2 (convexity; s the
    distance's slack), and two vectors a, b have |a / |a| - b / |b|| <= 2 |a - b| / |b|.
    """
    g1, g2 = k1.geometry, k2.geometry
    rl, moved, scale = abs(d), 0.0, 0.0
    for name in names:
        g = g2.geom_model.getGeometryId(name)
        radius = g2.sphere_radius[g]  # (swept sphere included)
        reach = np.linalg.norm(g2.sphere_centre[g]) + radius  # every point of the body within it
        M1, M2 = g1.geom_data.oMg[g], g2.geom_data.oMg[g]
        moved += (np.linalg.norm(M1.translation - M2.translation)
                  + np.linalg.norm(M1.rotation - M2.rotation, 2) * reach)
        rl += radius
        scale = max(scale, np.abs(M2.translation).max() + reach)
    slack = GJK_TOLERANCE * (1.0 + rl) + moved + DISTANCE_ROUNDING * scale
    least = abs(d) + 2 * g2.rounding - slack  # |x*|: both cores inflated by the rounding at least
    return slack, 4 * np.sqrt(2 * rl * slack + slack**2) / least


def _compare(pair, worst, tol=None):
    """Compare the two paths' pairs and distances (to ``tol`` if given), rows and torques."""
    (_, c1, _, _, k1), (_, c2, _, _, k2) = pair
    _check_placements(pair)
    a, b = k1.last_pairs, k2.last_pairs
    if tol is not None:  # depths to EPA's tolerance: pairs at equal depths may swap places,
        # and a QP on the edge of feasibility solve on one path only
        da, db = {p[:2]: p[2] for p in a}, {p[:2]: p[2] for p in b}
        common = sorted(set(da) & set(db))
        assert len(common) >= min(len(da), len(db)) - 2, (a, b)
        np.testing.assert_allclose([da[p] for p in common], [db[p] for p in common], rtol=0,
                                   atol=tol)
        worst['pairs'] += c1.solution_found() != c2.solution_found()
        return
    assert c1.solution_found() == c2.solution_found()
    # the same pairs, by distance; pairs at equal distances (a symmetric robot's) in either order
    assert sorted(p[:2] for p in a) == sorted(p[:2] for p in b), (a, b)
    at = {p[:2]: i for i, p in enumerate(b)}
    for p in a:
        d, slack = b[at[p[:2]]][2], _distance_slack(k1, k2, p[:2], p[2])[0]
        assert abs(p[2] - d) <= slack, (p, d, slack)
        worst['distances'] = max(worst.get('distances', 0.0), abs(p[2] - d) / slack)
    m = len(a)
    order = [at[p[:2]] for p in a] + list(range(m, len(k2.lb)))
    C2, lb2 = k2.C[order], k2.lb[order]
    fin = np.isfinite(lb2)
    assert np.array_equal(fin, np.isfinite(k1.lb))
    scale = max(1.0, np.abs(C2).max(), np.abs(lb2[fin]).max(initial=0.0))
    for i in range(len(k1.lb)):
        off = max(np.abs(k1.C[i] - C2[i]).max(),
                  abs(k1.lb[i] - lb2[i]) if fin[i] else 0.0) / scale
        # (a pair once face to face may keep another bound since: a bound relaxes from the
        # last one, which depended on the witness points)
        faced = worst.setdefault('faced', set())
        if off > 1e-9 and i < m and (_face_to_face(k1, k2, i, order[i])
                                     or a[i][:2] in faced):
            faced.add(a[i][:2])
            worst['faces'] = worst.get('faces', 0) + 1
            continue
        worst['rows'] = max(worst['rows'], off)
    if c2.solution_found():
        t1, t2 = c1.get_joint_torque_command(), c2.get_joint_torque_command()
        worst['tau'] = max(worst['tau'], np.abs(t1 - t2).max() / max(1.0, np.abs(t2).max()))
    worst['pairs'] = max(worst['pairs'], len(k2.last_pairs))


def _face_to_face(k1, k2, i, j):
    """
    Tell whether row i of k1 and row j of k2 are one pair whose witness points are not unique.

    Two parallel faces (a symmetric robot's twin links) are closest along a whole patch: the same
    distance and normal, witness points anywhere on it, each path's GJK ending at another (coal's
    distance objects keep state from their last call, and the paths compute different pairs).
    Both rows are then right; the torques are still compared.
    """
    k = int(k1._sel[i])
    r1 = k1.geometry.geom_data.distanceResults[k]
    r2 = k2.geometry.geom_data.distanceResults[int(k2._sel[j])]
    slack, turn = _distance_slack(k1, k2, k1.geometry.names_of(k), r1.min_distance)
    return (abs(r1.min_distance - r2.min_distance) <= slack
            and np.linalg.norm(r1.normal - r2.normal) <= turn
            and np.abs(r1.getNearestPoint1() - r2.getNearestPoint1()).max() > 1e-9)


CASES = {  # robot: (URDF, SRDF, task frame, floating base)
    'panda': ('panda_description/urdf/panda.urdf', 'panda_description/srdf/panda.srdf',
              'panda_hand', False),
    # no SRDF of its own: the trunk and the upper legs overlap at every pose (disabled here)
    'solo12': ('solo_description/robots/solo12.urdf', 'solo12.srdf', 'FL_FOOT', True),
}

SOLO12_SRDF = '<robot name="solo">' + ''.join(
    f'<disable_collisions link1="base_link" link2="{leg}_UPPER_LEG" reason="Never"/>'
    for leg in ('FL', 'FR', 'HL', 'HR')) + '</robot>'


def _srdf(name, example_robot_urdf, tmp_path):
    if name == 'solo12.srdf':
        (tmp_path / name).write_text(SOLO12_SRDF)
        return str(tmp_path / name)
    return example_robot_urdf(name)


def _share_history(pair):
    """
    Give the compiled path the reference's per-pair history (last bounds, their cycles, floors).

    Bodies inside each other have depths equal to EPA's tolerance only, so the two paths' bounds
    differ there; a bound's next values follow its last one (relaxing, or the braking margin's
    term tightening at a bounded rate), and the next states are compared from the same history.
    """
    (_, _, _, _, compiled), (_, _, _, _, reference) = pair
    for mine, theirs in zip(compiled.kept_bounds()[:3], reference.kept_bounds()[:3]):
        mine[:] = theirs


@pytest.mark.parametrize('case', sorted(CASES))
def test_kernels_equal_the_reference_on_random_states(case, example_robot_urdf, tmp_path):
    urdf, srdf, frame, floating = CASES[case]
    pair = _pair(example_robot_urdf(urdf), _srdf(srdf, example_robot_urdf, tmp_path), frame,
                 floating)
    robot = pair[0][0]
    model = robot.model
    rng = np.random.default_rng(11)
    worst = {'rows': 0.0, 'tau': 0.0, 'pairs': 0}
    deep = {'rows': 0.0, 'tau': 0.0, 'pairs': 0}
    dt, rows_seen, compared, k = 1e-3, 0, 0, 0
    lo = np.maximum(model.lowerPositionLimit, -3.0)
    hi = np.minimum(model.upperPositionLimit, 3.0)
    while compared < 500:
        if floating:  # the legs anywhere about the standing pose, the base tilted
            q = pin.neutral(model)
            q[3:7] = pin.Quaternion(pin.exp3(rng.normal(0.0, 0.3, 3))).coeffs()
            q[7:] += rng.normal(0.0, 0.5, model.nq - 7)
        else:  # (from this test's generator: Pinocchio's own is shared with whatever ran before,
            # collision_pairs.py's sampling reseeds it when it finds no cache file)
            q = rng.uniform(lo, hi)
        v = rng.normal(0.0, 1.0, model.nv)
        T = np.eye(4)
        T[:3, 3] = rng.uniform(-0.3, 0.6, 3)
        for r, c, ee, post, col in pair:
            r.set_configuration(q, v) if floating else r.set_robot_state(q, v)
            ee.servo_controller().set_desired(T)
            _move(col, k * dt)
            c.update(k * dt, dt)
        assert pair[0][4]._kernels is not None, pair[0][1].compiled_cycle.describe()
        k += 1
        if any(d < 0.0 for *_, d in pair[1][4].last_pairs + pair[0][4].last_pairs):
            _compare(pair, deep, tol=1e-6)
            _share_history(pair)
            continue
        _compare(pair, worst)
        compared += 1
        rows_seen += len(pair[1][4].last_pairs)
    rows, tau, faces = worst['rows'], worst['tau'], worst.get('faces', 0)
    most, one_path = worst['pairs'], deep['pairs']
    print(f'{case}: rows differ by {rows:.1e}, torques by {tau:.1e} (relative); '
          f'{rows_seen / 500:.1f} pairs with rows per state, at most {most}; '
          f'{k - compared} states with bodies inside each other (distances equal to 1e-6, '
          f'{one_path} solved on one path only); {faces} rows of pairs face to face '
          '(other witness points)')
    assert rows_seen > 500  # the states bring bodies within reach: rows are compared
    assert worst['rows'] <= 1e-9 and worst['tau'] <= 1e-9, worst


def test_kernels_equal_the_reference_along_a_run_and_skip_far_pairs(example_robot_urdf):
    """The Panda sweeping its hand past the ball, the reference's states fed to both."""
    from orca_ros.examples.common import integrate

    case = CASES['panda']
    pair = _pair(example_robot_urdf(case[0]), example_robot_urdf(case[1]), case[2], False)
    robot, ref = pair[1][0], pair[1][1]
    model = robot.model
    q0 = np.array([-0.7, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])
    q1 = q0.copy()
    q1[0] = 0.7
    data = model.createData()
    hand = model.getFrameId('panda_hand')
    ends = []
    for q in (q0, q1):
        pin.framesForwardKinematics(model, data, q)
        ends.append(data.oMf[hand].homogeneous.copy())
    q, v, dt = q0.copy(), np.zeros(model.nv), 1e-3
    worst = {'rows': 0.0, 'tau': 0.0, 'pairs': 0}
    for k in range(2000):
        s = min(1.0, k * dt / 2.0)
        T = ends[0].copy()
        T[:3, 3] += (10 * s**3 - 15 * s**4 + 6 * s**5) * (ends[1][:3, 3] - ends[0][:3, 3])
        for r, c, ee, post, col in pair:
            r.set_robot_state(q, v)
            ee.servo_controller().set_desired(T)
            post.set_desired(q0)
            _move(col, k * dt)
            c.update(k * dt, dt)
        _compare(pair, worst)
        q, v = integrate(robot, q, v, ref.get_joint_torque_command(), dt)
    computed, skipped = pair[0][4]._kernels.counts
    rows, tau, most, dist = worst['rows'], worst['tau'], worst['pairs'], worst['distances']
    print(f'rows differ by {rows:.1e}, torques by {tau:.1e}; distances by {dist:.1e} of their '
          f'slack; up to {most} pairs with rows; distances computed {computed}, skipped {skipped}')
    assert worst['pairs'] >= 4
    assert skipped > 0.1 * (computed + skipped)  # the far pairs' distances were not recomputed
    assert worst['rows'] <= 1e-9 and worst['tau'] <= 1e-9, worst


def test_kernels_follow_obstacles_added_and_removed(example_robot_urdf):
    """Obstacles removed, added again and moved mid-run: the kernels' pairs follow (rebuilds)."""
    from orca_ros.examples.common import integrate

    case = CASES['panda']
    pair = _pair(example_robot_urdf(case[0]), example_robot_urdf(case[1]), case[2], False)
    for *_, col in pair:  # the ball goes 10 cm into panda_link5: taken, as deep pairs are compared
        col.max_depth = 0.2
    robot = pair[1][0]
    q = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])
    v = np.zeros(robot.model.nv)
    hand = None
    worst = {'rows': 0.0, 'tau': 0.0, 'pairs': 0}
    near = np.eye(4)
    dt = 1e-3
    for k in range(600):
        for r, c, ee, post, col in pair:
            r.set_robot_state(q, v)
            if k == 0:
                hand = r.get_frame_pose('panda_hand')
                near[:3, 3] = hand[:3, 3] + [0.0, 0.16, 0.0]
            ee.servo_controller().set_desired(hand)
            post.set_desired(q)
            if k == 100:
                col.remove_obstacle('ball')
                col.remove_obstacle('bar')
            if k == 200:
                col.add_obstacle('ball', 'sphere', [0.1], near)
            if 300 <= k < 400:
                moved = near.copy()
                moved[1, 3] -= 0.0002 * (k - 300)  # towards the hand, 0.2 m/s
                col.move_obstacle('ball', moved, velocity=[0.0, -0.2, 0.0])
            if k == 400:
                col.remove_obstacle('ball')
            c.update(k * dt, dt)
        _compare(pair, worst)
        names = {n for p in pair[0][4].last_pairs for n in p[:2]}
        if 100 <= k < 200 or k >= 400:
            assert not any(n.startswith('obstacle:ball') for n in names), (k, names)
        if 200 <= k < 250:  # put 16 cm from where the hand was: the arm is pushed away
            assert 'obstacle:ball' in names, (k, names)
        q, v = integrate(robot, q, v, pair[1][1].get_joint_torque_command(), dt)
    assert worst['rows'] <= 1e-9 and worst['tau'] <= 1e-9, worst


def test_a_view_lost_mid_run_falls_back_to_python(example_robot_urdf, monkeypatch):
    """A rebuild whose views do not check out: one error line, then the rows in Python."""
    from orca_ros.constraint import collision_kernel as ck

    case = CASES['panda']
    pair = _pair(example_robot_urdf(case[0]), example_robot_urdf(case[1]), case[2], False)
    q = np.array([-0.7, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785, 0.02, 0.02])
    v = np.zeros(9)
    worst = {'rows': 0.0, 'tau': 0.0, 'pairs': 0}
    for k in range(20):
        if k == 10:  # another Pinocchio, say: the next rebind finds no view
            monkeypatch.setattr(ck, 'placement_view', lambda gd, count: None)
        for r, c, ee, post, col in pair:
            r.set_robot_state(q, v)
            if k == 10:
                col.remove_obstacle('bar')  # a rebuild
            c.update(k * 1e-3, 1e-3)
        _compare(pair, worst)
    assert pair[0][4]._kernels is None  # the Python path from then on
    assert pair[1][1].solution_found()
    assert worst['rows'] <= 1e-9 and worst['tau'] <= 1e-9, worst
