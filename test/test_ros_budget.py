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
The controller node's timer loop under its shipped budget, with a QP that fails every cycle.

The node runs as shipped (``config/lwr_controller.yaml``: 1 kHz timer, DAQP, solve budget one
period) beside the free-running bridge; its torque limits of 0.1 Nm cannot hold the arm and its
velocity limits of 1 mrad/s do not let it fall, so every QP is infeasible and every cycle sends the
safe command (which holds the arm where it is: the QP stays infeasible). The node is its own
process: the suite's offline budget (conftest) does not reach it; the marker says what the test is
about.

What a shared machine lets a test claim about a period (see test_budget.py): the loop's own work
per cycle (the CPU time of the node's control thread, from /proc) must fit in the period whatever
the load; the periods it loses must be ones the machine took (time its control thread waited for a
CPU, also from /proc), never ones its own work took. Measured (a 2-core machine, others'
tests beside it): 0.38 ms of CPU per failing cycle (0.33-0.39 ms per solved cycle; OSQP, failing:
0.72 ms), 2-26 % of the periods lost while the thread waited 1.4-2.0 s of 3.2 s for a CPU; on a
slower 2-core machine (a pure-Python loop 2.5x slower) 0.77 ms failing (0.64-1.08 ms before a
failed solve's set-up got lighter), 0.60 ms solved. How much of the period the work takes is a
speed target and lives in bench/bench_node_cpu.py.
"""


import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
from orca_ros.utils.schedstat import thread_schedstat
import pytest

pytestmark = pytest.mark.real_time_budget

PERIOD = 1e-3  # the shipped update_rate, 1 kHz


def _schedstat(pid: int):
    """Return (CPU time, time waiting on a run queue) [s] of process ``pid``'s main thread."""
    got = thread_schedstat(pid)
    if got is None:
        pytest.skip(f'/proc/{pid}/task/{pid}/schedstat not available (a Linux kernel with '
                    'schedstats is needed)')
    return got


def _report(probe, pid):
    """
    Wait for the next diagnostics report; return its time, itself, the schedstat, the commands.

    The time is the node's own, the report's stamp: the probe, a process beside the node, may
    receive it tens of ms late on a loaded machine, which a wall time taken here would count as
    periods the loop lost.
    """
    before = probe.diagnostics.get('cycles')
    probe.wait_for(lambda: probe.diagnostics.get('cycles') != before, 30, 'a diagnostics report')
    with probe.lock:
        diag = dict(probe.diagnostics)
        n_commands = len(probe.commands)
    return diag['_stamp'], diag, _schedstat(pid), n_commands


def test_timer_loop_keeps_its_period_and_its_fallback_under_a_failing_qp(tmp_path):
    domain = free_domain_id()
    procs = Procs(domain, str(tmp_path))
    procs.start_arm(
        'free_running',
        controller_args=(
            '-p',
            'constraints.torque_limit.max:=0.1',
            '-p',
            'constraints.velocity_limit.max:=0.001',
            # normal scheduling, whose lost periods this test accounts for (the time the loop
            # waited for a CPU). At SCHED_FIFO (the default where allowed) the loop waits for
            # none; beside two CPU burners it still lost 3.9-5.2 % of its periods by the node's
            # own clock, not yet explained (at normal priority: 59 %, all accounted for)
            '-p',
            'thread_priority:=0',
        ),
        bridge_args=('-p', 'rate:=1000.0'),
    )
    probe = Probe(domain)
    try:
        pid = procs.procs[1][0].pid
        probe.wait_for(lambda: int(probe.diagnostics.get('qp_failures', 0)) > 1000, 120,
                       'a spell of failed cycles')
        probe.wait_for(lambda: probe.last_state() is not None, 60, 'joint states')
        q0 = probe.last_state()[1]
        t0, d0, (cpu0, wait0), n0 = _report(probe, pid)
        probe.wait_for(lambda: int(probe.diagnostics.get('cycles', 0)) > int(d0['cycles']) + 3000,
                       120, '3000 more cycles')
        t1, d1, (cpu1, wait1), n1 = _report(probe, pid)
        q1 = probe.last_state()[1]
        with probe.lock:
            commands = np.array(probe.commands[n0:n1])
    finally:
        probe.close()
        procs.stop()
    cycles = int(d1['cycles']) - int(d0['cycles'])
    failures = int(d1['qp_failures']) - int(d0['qp_failures'])
    assert d1['solver'] == 'daqp' and d1['solver_budget'] == 'one period, default iterations'
    # the fallback: every cycle failed and sent the safe command, finite and within the torques
    assert failures == cycles
    assert d1['_level'] == 2 and 'safe command: no QP solution' in d1['_message'], d1['_message']
    # one command per cycle, counted by the node: the solved ones', and those of the cycles that
    # found the state stale (no solve: the safe command; one in a CI run, 3096 commands in 3095
    # solves); the probe, a Python subscriber sharing the machine, receives a sample of them
    # (under load fewer: 2765 of 3215 beside two CPU burners) whose content is checked
    ran = int(d1['loop_cycles']) - int(d0['loop_cycles'])
    print(f'{cycles} cycles solved, {ran - cycles} sent the safe command on a stale state')
    assert int(d1['commands_sent']) - int(d0['commands_sent']) == ran >= cycles
    assert commands.shape[0] >= 300
    assert np.isfinite(commands).all() and np.abs(commands).max() <= 176.0
    # ... and held the arm (gravity and damping at the measured state)
    assert np.abs(q1 - q0).max() < 0.05, q1 - q0
    # the period: where the loop's own work fits in it, it lost only periods the machine took: a
    # late cycle waited at least the period less the work for a CPU (waiting 0 s, the loop keeps
    # every period but 5 %). Whether the work fits is the machine's speed, a target of
    # bench/bench_node_cpu.py (0.6 of the period), not of a test: a slow CI machine's 3.12 took
    # 1.07 ms of CPU per 1 ms cycle, and a loop that works longer than its period cannot keep it
    work = (cpu1 - cpu0) / cycles
    wall, waited = t1 - t0, wait1 - wait0
    lost = wall - cycles * PERIOD
    if work < PERIOD:
        assert lost <= 0.05 * wall + waited / (1.0 - work / PERIOD), (
            f'{lost:.3f} s of {wall:.3f} s lost, {waited:.3f} s waiting for a CPU'
        )
    print(f'\n{cycles} cycles in {wall:.2f} s ({lost / wall:.1%} lost), {work * 1e3:.3f} ms CPU '
          f'per cycle, {waited:.3f} s waiting for a CPU; loop period mean '
          f"{d1['loop_period_mean_ms']} ms, solve median {d1['solve_time_median_us']} us")
