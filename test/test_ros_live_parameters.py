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
Live parameters.

A gain change takes effect as the control law predicts; bad or structural changes are refused with
a reason (lockstep: times are simulated).
"""

import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest


def set_params(probe, atomically=False, **values):
    from rcl_interfaces.srv import SetParameters, SetParametersAtomically
    from rclpy.parameter import Parameter

    srv = SetParametersAtomically if atomically else SetParameters
    req = srv.Request()
    req.parameters = [
        Parameter(k.replace('__', '.'), value=v).to_parameter_msg() for k, v in values.items()
    ]
    res = probe.call(
        srv,
        f"/orca_controller/{'set_parameters_atomically' if atomically else 'set_parameters'}",
        req,
    )
    return [res.result] if atomically else res.results


def rise_time(probe, step=0.01, fraction=0.9, tries=5):
    """
    Measure the simulated time to cover ``fraction`` of a ``step`` along x.

    From the last state at rest to the first state past ``fraction``, each next to the state
    before it (1 ms): best-effort states can be lost on a busy machine, and a gap there (once
    0.1 s) would add to the time. A measurement with a gap at either end is made again, with
    another step from where the arm is.
    """
    for _ in range(tries):
        start = probe.ee_pose()
        target = start.copy()
        target[:3, 3] += [step, 0.0, 0.0]
        n0 = len(probe.states)
        probe.send_target('ee', target, until=probe.moved_towards(target, 1e-4))
        probe.wait_sim(1.5)
        states = probe.states[n0:]
        x = np.array([probe.ee_pose(s[1])[0, 3] - start[0, 3] for s in states])
        t = np.array([s[0] for s in states])
        moving = np.flatnonzero(np.abs(x) > 1e-5)[0]  # the first cycle that acts on the target
        reached = np.flatnonzero(x * np.sign(step) > fraction * abs(step))[0]
        if moving > 0 and max(t[moving] - t[moving - 1], t[reached] - t[reached - 1]) < 1.5e-3:
            return t[reached] - t[moving - 1]
    raise AssertionError(f'joint states lost around the step in each of {tries} tries')


def test_gain_change_applies_and_bad_changes_are_refused(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    # steps go straight to the servo here, so the PD law alone sets the response
    procs.start_arm('lockstep', controller_args=('-p', 'tasks.ee.trajectory.enabled:=false'))
    probe = Probe(domain)
    try:
        probe.wait_for(lambda: probe.sim_time() > 1.0, 60, 'the controller driving the bridge')
        # critically damped PD (kd = 2 sqrt(kp)): 90 % rise time = 3.89 / sqrt(kp)
        t_400 = rise_time(probe)
        res = set_params(probe, tasks__ee__kp=[100.0] * 6, tasks__ee__kd=[20.0] * 6)
        assert all(r.successful for r in res), [r.reason for r in res]
        t_100 = rise_time(probe)
        assert t_400 == pytest.approx(3.89 / 20.0, rel=0.2) and t_100 == pytest.approx(
            3.89 / 10.0, rel=0.2
        ), (t_400, t_100)
        assert t_100 / t_400 == pytest.approx(2.0, rel=0.15)

        refused = {
            'solver': ('banana', 'read-only at run time'),
            'update_rate': (0.0, 'read-only at run time'),
            'tasks.ee.kp': ([-5.0] * 6, 'outside [0, 1e+06]'),
            'tasks.ee.kd': ([1.0, 2.0], 'needs 1 or 6 values'),
            'tasks.ee.weight': (float('nan'), 'outside'),
            'safe_damping': (1e9, 'outside'),
        }
        for name, (value, reason) in refused.items():
            res = set_params(probe, **{name.replace('.', '__'): value})
            assert not res[0].successful and reason in res[0].reason, (name, res[0].reason)
        # all or nothing: the valid half of a refused request is not applied either
        res = set_params(
            probe, atomically=True, tasks__ee__kp=[50.0] * 6, tasks__ee__kd=[-1.0] * 6
        )
        assert not res[0].successful and 'tasks.ee.kd' in res[0].reason
        assert rise_time(probe, step=-0.01) == pytest.approx(t_100, rel=0.15)
        # the solve budget: 1 s by default in lockstep (the simulation waits), changed live, both
        # at once
        probe.wait_for(
            lambda: probe.diagnostics.get('solver_budget') == '1000 ms, default iterations',
            60,
            'the lockstep default budget in the diagnostics',
        )
        res = set_params(
            probe, atomically=True, solver_time_budget=0.02, solver_max_iterations=200
        )
        assert res[0].successful, res[0].reason
        probe.wait_for(
            lambda: probe.diagnostics.get('solver_budget') == '20 ms, 200 iterations',
            60,
            'the new budget in the diagnostics',
        )
        res = set_params(probe, solver_max_iterations=-3)
        assert not res[0].successful and 'outside' in res[0].reason
        log = procs.log('controller')
        assert "parameter change rejected: 'solver' is read-only" in log and 'Traceback' not in log
    finally:
        probe.close()
        procs.stop()
