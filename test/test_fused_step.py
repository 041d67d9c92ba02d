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
The one-call cycle (optim/compiled/fused_step.py) against the compiled cycle's three calls.

Controllers on the same arm see the same states and targets: one runs the one call inline
(the compiled cycle's lean route), one through ``CompiledCycle.update``, one has its one-call path
taken away. Along a run whose problem turns infeasible and back, and whose locked joint is
welded again (a new Pinocchio model and Data): the same return codes and the same torques,
the one-call path taken on every cycle that starts warm. With levels below (strict and
generalized priorities), the first level by one call and the rest by the cascade: the same
closed loop. The kernel's clock, which times the
solve for the solver's time model, reads what ``time.monotonic_ns`` reads.
"""

import time

import numpy as np
import orca_ros as orca
from orca_ros.optim.solvers import ReturnCode
from orca_ros.paths import default_urdf_path
import pytest

pytest.importorskip('numba')
pytest.importorskip('daqp')

from orca_ros.optim.solvers import clock  # noqa: E402,I100

Q0 = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.6])


def _controller(one_call: bool, lean: bool = True):
    robot = orca.RobotModel()
    robot.load_model_from_file(default_urdf_path())
    robot.lock_joints(['joint_6'], [0.1])
    robot.set_robot_state(Q0, np.zeros(6))
    c = orca.Controller('c', robot)
    ee = c.add_task(orca.CartesianTask, 'ee')
    ee.set_control_frame('link_7')
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(1e-4)
    posture.set_desired(Q0, np.zeros(6), np.zeros(6))
    for lim in (orca.JointTorqueLimitConstraint, orca.JointPositionLimitConstraint,
                orca.JointVelocityLimitConstraint, orca.JointAccelerationLimitConstraint):
        c.add_constraint(lim, lim.__name__)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 1e-3)
    cc = c.compiled_cycle
    assert cc.fused is not None, cc.describe()
    calls = []
    if one_call:  # count the kernel's calls (bound again with a new model)
        fused, bind = cc.fused, cc.fused.bind

        def counting(ws):
            bind(ws)
            step = fused.kernel
            fused.kernel = lambda *a: calls.append(1) or step(*a)
            if not lean:  # the lean route of CompiledCycle.run taken away
                fused.lean = None

        fused.bind = counting
        counting(cc.ws)
    else:
        cc.fused = None
    # the cycles that ran CompiledCycle.update (the others: the lean route of CompiledCycle.run)
    cc.updates, update = [], cc.update
    cc.update = lambda *a: cc.updates.append(1) or update(*a)
    return robot, c, ee, calls


def test_the_one_call_cycle_equals_the_three_calls_through_failures_and_a_weld():
    # the one call inline in CompiledCycle.run (lean) and through CompiledCycle.update, and
    # the three calls
    runs = [_controller(True), _controller(True, lean=False), _controller(False)]
    pose = runs[0][0].get_frame_pose('link_7').copy()
    limits = {}
    for _, c, _, _ in runs:
        for name in ('JointTorqueLimitConstraint', 'JointAccelerationLimitConstraint'):
            limits[name] = c.get_constraint(name).get_limits()
    codes, warm, not_lean = [], [], []
    for k in range(1, 400):
        t = k * 1e-3
        if k == 150:  # no torque both holds the arm and keeps within these
            for _, c, _, _ in runs:
                c.get_constraint('JointTorqueLimitConstraint').set_limits(-0.1, 0.1)
                c.get_constraint('JointAccelerationLimitConstraint').set_limits(-1e-3, 1e-3)
        if k == 180:
            for _, c, _, _ in runs:
                for name, lim in limits.items():
                    c.get_constraint(name).set_limits(*lim)
        if k == 250:  # the locked joint moved: a new model and Data
            data = runs[0][0].data
            assert all(r.set_locked_joint_positions([0.3]) for r, _, _, _ in runs)
            assert runs[0][0].data is not data
        target = pose.copy()
        target[:3, 3] += 0.1 * np.array([np.sin(3 * t), np.cos(2 * t) - 1.0, np.sin(t)])
        q = Q0 + 0.2 * np.sin(np.arange(1, 7) * 2.0 * t)
        v = 0.4 * np.cos(np.arange(1, 7) * 2.0 * t)
        warm.append(runs[0][1].compiled_cycle.fused.backend.warm)  # (DAQP's warm start)
        updates = len(runs[0][1].compiled_cycle.updates)
        out = []
        for robot, c, ee, _ in runs:
            robot.set_robot_state(q, v)
            ee.servo_controller().set_desired(target)
            out.append((c.update(t, 1e-3), c.get_return_code(), c.get_joint_torque_command()))
        ok, code, tau = out[0]
        for ok3, code3, tau3 in out[1:]:
            assert (ok, code) == (ok3, code3), k
            np.testing.assert_allclose(tau, tau3, rtol=1e-12, atol=1e-12, err_msg=str(k))
        codes.append(code)
        if warm[-1] and len(runs[0][1].compiled_cycle.updates) > updates:
            not_lean.append(k)
    failed = [k for k, code in enumerate(codes, 1) if code is not ReturnCode.SUCCESS]
    assert failed == list(range(150, 180)), failed
    # every cycle that starts warm (the one before it solved) took the one call
    assert sum(warm) == len(runs[0][3]) >= len(codes) - 40
    # DAQP's workspace is kept through the failures (a failed solve restarts cold in place,
    # DirectDAQPBackend.restart): every cycle but the first starts on it
    assert all(warm[1:])
    assert len(runs[1][3]) == len(runs[0][3])  # the one call, lean or not
    # lean: every warm cycle but those after a change, where CompiledCycle.update re-reads the
    # objects: the first, the limits set (150) and restored (180), each change's re-read
    # limits making the next cycle re-read too (151, 181), the weld (a new Data bound)
    assert not_lean == [1, 150, 151, 180, 181, 250], not_lean
    assert len(runs[1][1].compiled_cycle.updates) == len(codes)
    # the time model of the one-call path: the solve's time by the kernel's clock
    b = runs[0][1].compiled_cycle.problem.backend
    assert 0.0 < b.timing[0] < 1e-3


def test_the_kernels_clock_reads_the_monotonic_clock():
    assert clock.unavailable_reason() is None
    fn = clock.address()
    for _ in range(100):
        before = time.monotonic_ns()
        ours = clock._read(fn)
        after = time.monotonic_ns()
        assert before <= ours <= after
        first = time.perf_counter()  # deadlines are its instants
        assert first - 1e-6 <= clock._read(fn) * 1e-9 <= time.perf_counter() + 1e-6


@pytest.mark.parametrize('strategy', ['multi_level_weighted', 'generalized'])
def test_levels_below_follow_the_one_call_first_level(strategy):
    """The first level by one call (inline), the levels below by the cascade: the same loop."""
    from orca_ros.examples.common import (
        add_conflicting_stack, add_standard_constraints, integrate, STACK_Q0,
    )

    runs = []
    for one_call in (True, False):
        robot = orca.RobotModel()
        robot.load_model_from_file(default_urdf_path())
        robot.set_robot_state(STACK_Q0, np.zeros(7))
        c = orca.Controller('c', robot, strategy)
        add_conflicting_stack(c, 3)
        add_standard_constraints(c)
        if strategy == 'generalized':  # priority 0.5 between every pair of levels
            names = [t.name for t in c.get_tasks()]
            for i, hi in enumerate(names):
                for lo in names[i + 1:]:
                    c.set_priority(hi, lo, 0.5)
        c.activate_tasks_and_constraints()
        assert c.update(0.0, 1e-3)
        cc = c.compiled_cycle
        assert cc.fused is not None and cc.cascade is not None, cc.describe()
        calls = []
        if one_call:  # the first level by one call; in the lean route, every level below too
            step, cs = cc.fused.kernel, cc.fused.cascade_step
            cc.fused.kernel = lambda *a, step=step, calls=calls: calls.append(1) or step(*a)
            cs.run = lambda *a, run=cs.run, calls=calls: calls.append(2) or run(*a)
        else:
            cc.fused = None
        cc.updates, update = [], cc.update  # the cycles through CompiledCycle.update
        cc.update = lambda *a, cc=cc, update=update: cc.updates.append(1) or update(*a)
        runs.append((robot, c, calls))
    q, v = STACK_Q0.copy(), np.zeros(7)
    for k in range(1, 300):
        out = []
        for robot, c, _ in runs:
            robot.set_robot_state(q, v)
            assert c.update(k * 1e-3, 1e-3)
            out.append(c.get_joint_torque_command())
        np.testing.assert_allclose(out[0], out[1], rtol=1e-12, atol=1e-12, err_msg=str(k))
        q, v = integrate(runs[0][0], q, v, out[0], 1e-3)
    assert len(runs[0][2]) == 299
    # the lean route, the levels below in the same kernel call, on every one but
    # the first (which re-reads what the configuring cycle touched: nothing changed since)
    assert runs[0][2].count(2) == 298
    assert len(runs[0][1].compiled_cycle.updates) == 1
    assert len(runs[1][1].compiled_cycle.updates) == 299
    assert np.linalg.norm(v) > 0.1  # the stack moved the arm
