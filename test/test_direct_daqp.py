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
DAQP's C solve by kernel (optim/solvers/direct_daqp.py) against the daqp package's wrapper.

The same QPs in the same order through both: the same return codes and the same solutions,
warm starts, failures and cold restarts included; a wrong structure layout is refused before
any solve is used, and the controller then keeps the wrapper; set-ups do not leak DAQP's memory.
"""

import ctypes

import numpy as np
import orca_ros as orca
from orca_ros.optim.solvers import make_backend, QPSolver, ReturnCode
from orca_ros.paths import default_urdf_path
import pytest

pytest.importorskip('numba')
pytest.importorskip('daqp')

from orca_ros.optim.solvers import daqp_c, direct_daqp  # noqa: E402,I100


def _qp(rng, nx, ne, ni, infeasible=False):
    """Return a strictly convex QP in DAQP's stacked layout (some bounds infinite)."""
    R = rng.standard_normal((nx, nx))
    H = R @ R.T + 0.1 * np.eye(nx)
    g = rng.standard_normal(nx)
    M = rng.standard_normal((ne + ni, nx))
    lbox, ubox = -rng.uniform(0.5, 2.0, nx), rng.uniform(0.5, 2.0, nx)
    lbox[::3], ubox[1::4] = -np.inf, np.inf
    b = 0.1 * rng.standard_normal(ne)
    lo_in = -rng.uniform(0.0, 1.0, ni)
    hi_in = rng.uniform(0.0, 1.0, ni)
    lo_in[::5] = -np.inf
    if infeasible:  # a row that cannot be met inside the box: l > |row| * box
        lo_in[0] = np.sum(np.abs(M[ne]) * np.maximum(np.abs(lbox), np.abs(ubox))) + 1.0
        lo_in[0] = min(lo_in[0], 1e6)
        hi_in[0] = lo_in[0] + 1.0
    lo = np.concatenate([lbox, b, lo_in])
    hi = np.concatenate([ubox, b, hi_in])
    return H, g, M, lo, hi


def _pair(nx, ne, ni, scale):
    reference = make_backend(QPSolver.DAQP, nx, ne, ni, scale=scale)
    return reference, direct_daqp.DirectDAQPBackend(nx, ne, ni, scale=scale)


@pytest.mark.parametrize('scaled', [False, True])
def test_same_codes_and_solutions_as_the_wrapper(scaled):
    rng = np.random.default_rng(7)
    nx, ne, ni = 12, 3, 9
    scale = np.r_[np.ones(8), np.full(4, 150.0)] if scaled else None
    reference, direct = _pair(nx, ne, ni, scale)
    H, g, M, lo, hi = _qp(rng, nx, ne, ni)
    codes, worst, failures = [], 0.0, 0
    for k in range(300):
        # mostly small changes (warm starts from the last active set), now and then a new
        # problem, and an infeasible one every 25 cycles (then a cold restart on both sides)
        if k % 25 == 24:
            H, g, M, lo, hi = _qp(rng, nx, ne, ni, infeasible=True)
        elif k % 25 == 0:
            H, g, M, lo, hi = _qp(rng, nx, ne, ni)
        else:
            g = g + 0.05 * rng.standard_normal(nx)
        a = reference.solve_stacked(H, g, M, lo, hi)
        b = direct.solve_stacked(H, g, M, lo, hi)
        assert a is b, f'cycle {k}: wrapper {a}, kernel {b}'
        assert reference.iterations == direct.iterations
        codes.append(b)
        if b is ReturnCode.SUCCESS:
            worst = max(worst, np.max(np.abs(direct.x - reference.x)) / max(1.0, np.max(np.abs(
                reference.x))))
        else:
            failures += 1
    # the same C code on the same data in the same order: the same floating-point operations
    assert worst == 0.0
    assert failures == 12 and codes.count(ReturnCode.PRIMAL_INFEASIBLE) == 12
    # each problem after an infeasible one solved (cold restart)
    assert all(codes[k] is ReturnCode.SUCCESS for k in range(25, 300, 25))


def test_crossed_bounds_fail_without_a_solve_and_recover():
    rng = np.random.default_rng(3)
    reference, direct = _pair(6, 0, 4, None)
    H, g, M, lo, hi = _qp(rng, 6, 0, 4)
    for b in (reference, direct):
        assert b.solve_stacked(H, g, M, lo, hi) is ReturnCode.SUCCESS
    bad_lo = lo.copy()
    bad_lo[6] = hi[6] + 1.0  # lower bound above the upper one
    codes = [b.solve_stacked(H, g, M, bad_lo, hi) for b in (reference, direct)]
    assert codes[0] is codes[1] and codes[1] is not ReturnCode.SUCCESS
    for b in (reference, direct):
        assert b.solve_stacked(H, g, M, lo, hi) is ReturnCode.SUCCESS
    np.testing.assert_array_equal(direct.x, reference.x)


class _Shifted(ctypes.Structure):
    """A workspace head one int off: what an upgraded DAQP with a new first field would be."""

    _fields_ = [('extra', ctypes.c_int)] + list(daqp_c.WorkspaceHead._fields_)


def test_a_wrong_layout_is_refused_before_any_solve(monkeypatch):
    rng = np.random.default_rng(1)
    H, g, M, lo, hi = _qp(rng, 5, 1, 3)
    monkeypatch.setattr(daqp_c, 'WorkspaceHead', _Shifted)
    b = direct_daqp.DirectDAQPBackend(5, 1, 3)
    with pytest.raises(daqp_c.LayoutError):
        b.solve_stacked(H, g, M, lo, hi)
    monkeypatch.setattr(direct_daqp, '_CHECKED', [])
    assert 'do not match' in direct_daqp.unavailable_reason()


def test_a_workspace_is_freed_with_the_layout_it_was_made_with(monkeypatch):
    """
    A backend collected while the module's layout is another one frees its workspace right.

    The finalizer took our settings out of DAQP's workspace through the layout looked up when the
    collector ran: under the wrong-layout tests' ``_Shifted``, a backend of an earlier test
    collected then wrote the null eight bytes off, DAQP freed numpy's settings buffer, and numpy
    freed it again (the suite aborted: "double free or corruption"). Here DAQP's free is watched:
    it must find the settings pointer null (else the watcher leaks instead of freeing).
    """
    import gc

    rng = np.random.default_rng(3)
    H, g, M, lo, hi = _qp(rng, 5, 1, 3)
    b = direct_daqp.DirectDAQPBackend(5, 1, 3)
    assert b.solve_stacked(H, g, M, lo, hi) is ReturnCode.SUCCESS  # our settings in its workspace
    real_head, lib = daqp_c.WorkspaceHead, daqp_c.library()
    free, settings_at_free = lib.free_workspace, []

    def watched(address):
        ours = bool(real_head.from_address(address).settings)
        settings_at_free.append(ours)
        if not ours:
            free(address)

    monkeypatch.setattr(lib, 'free_workspace', watched)
    monkeypatch.setattr(daqp_c, 'WorkspaceHead', _Shifted)
    del b
    gc.collect()  # and whatever earlier tests left for the collector: every one must free right
    assert settings_at_free and not any(settings_at_free)


def _arm_controller():
    robot = orca.RobotModel()
    robot.load_model_from_file(default_urdf_path())
    q = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0])
    robot.set_robot_state(q, np.zeros(7))
    c = orca.Controller('c', robot)
    t = c.add_task(orca.CartesianTask, 'ee')
    t.set_control_frame('link_7')
    target = robot.get_frame_pose('link_7').copy()
    target[:3, 3] += [0.05, -0.05, 0.05]
    t.servo_controller().set_desired(target)
    for lim in (orca.JointTorqueLimitConstraint, orca.JointPositionLimitConstraint):
        c.add_constraint(lim, lim.__name__)
    c.activate_tasks_and_constraints()
    return robot, c


def test_the_controller_falls_back_to_the_wrapper_on_a_wrong_layout(monkeypatch, caplog):
    monkeypatch.setattr(daqp_c, 'WorkspaceHead', _Shifted)
    monkeypatch.setattr(direct_daqp, '_CHECKED', [])
    robot, c = _arm_controller()
    assert c.update(0.0, 1e-3)
    assert not c.compiled_cycle.solver_in_kernel
    assert 'do not match' in caplog.text
    tau = c.get_joint_torque_command()
    monkeypatch.undo()
    monkeypatch.setattr(direct_daqp, '_CHECKED', [])
    robot2, c2 = _arm_controller()
    assert c2.update(0.0, 1e-3)
    assert c2.compiled_cycle.solver_in_kernel
    assert 'first level solved by DAQP in the kernel' in c2.compiled_cycle.describe()
    np.testing.assert_allclose(c2.get_joint_torque_command(), tau, rtol=1e-12, atol=1e-12)


def _rss_kb() -> int:
    with open('/proc/self/statm') as fh:
        return int(fh.read().split()[1]) * 4


def test_set_ups_do_not_leak():
    rng = np.random.default_rng(5)
    nx, ne, ni = 30, 6, 30
    b = direct_daqp.DirectDAQPBackend(nx, ne, ni)
    H, g, M, lo, hi = _qp(rng, nx, ne, ni)
    for _ in range(200):  # warm up the allocator
        b.reset()
        assert b.solve_stacked(H, g, M, lo, hi) is ReturnCode.SUCCESS
    before = _rss_kb()
    for _ in range(3000):
        b.reset()
        assert b.solve_stacked(H, g, M, lo, hi) is ReturnCode.SUCCESS
    # each set-up allocates ~25 kB in DAQP (L, D, lam... for 96 constraints): 3000 leaked
    # set-ups would be ~70 MB
    assert _rss_kb() - before < 4000
