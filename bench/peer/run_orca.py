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
One scenario of scenarios.py run with orca_ros (default settings); prints one JSON line.

Timed per step: set_robot_state + Controller.update() + reading the torque command (what the node
does between a new state and its command). ``--floor`` times instead the least any Python
controller on this stack spends on the same problem: one Pinocchio computeAllTerms + one
warm-started solve of the controller's own QP of that step (captured beforehand, in the solver's
units and layout: see qp_solvers.py), by the default solver (DAQP) unless ``--solver`` names
another (daqp, proxqp, osqp, piqp).

Usage: python run_orca.py SCENARIO [--steps N] [--solver NAME] [--floor]
"""

from __future__ import annotations

import argparse
import gc
import json
import time

import numpy as np
import orca_ros as orca
import pinocchio as pin
import scenarios as S


def build(sc, solver=None):
    robot = orca.RobotModel()
    robot.load_model_from_file(S.urdf_path(sc), floating_base=sc['floating'])
    model = robot.model
    q = S.initial_configuration(sc, model)
    v = np.zeros(model.nv)
    if sc['floating']:
        robot.set_base_frame('world')
    set_state(robot, q, v)
    kw = {} if solver is None else {'solver': solver}
    c = orca.Controller('bench', robot, **kw)
    h = {}
    if 'ee' in sc:
        e = sc['ee']
        t = c.add_task(orca.CartesianTask, 'ee')
        t.set_control_frame(e['frame'])
        t.set_weight(e['weight'])
        pid = t.servo_controller().pid()
        pid.set_proportional_gain(e['kp'])
        pid.set_derivative_gain(e['kd'])
        h['ee'] = (t, robot.get_frame_pose(e['frame']), e['amplitude'])
    if 'com' in sc:
        e = sc['com']
        t = c.add_task(orca.CoMTask, 'com')
        t.set_weight(e['weight'])
        t.pid().set_proportional_gain(e['kp'])
        t.pid().set_derivative_gain(e['kd'])
        h['com'] = (t, robot.get_center_of_mass(), e['amplitude'])
    p = sc['posture']
    post = c.add_task(orca.JointAccelerationTask, 'posture')
    post.set_weight(p['weight'])
    post.pid().set_proportional_gain(p['kp'])
    post.pid().set_derivative_gain(p['kd'])
    post.set_desired(robot.get_joint_positions())
    if 'points' in sc:
        cp = sc['points']
        for f in cp['frames']:
            ct = orca.Contact(f, f)
            ct.set_friction_coefficient(cp['mu'])
            ct.set_maximum_normal_force(cp['fmax'])
            c.add_constraint(ct)
    if 'soles' in sc:
        cp = sc['soles']
        for f in cp['frames']:
            c.add_constraint(
                orca.SurfaceContact(
                    f,
                    f,
                    S.sole_corners(sc),
                    friction_coefficient=cp['mu'],
                    maximum_normal_force=cp['fmax'],
                )
            )
    lim = {
        'torque': orca.JointTorqueLimitConstraint,
        'position': orca.JointPositionLimitConstraint,
        'velocity': orca.JointVelocityLimitConstraint,
    }
    for name in sc['limits']:
        c.add_constraint(lim[name], f'{name}_limit')
    for obj in c.get_tasks() + c.get_constraints():
        obj.set_ramp_duration(0.0)
    c.activate_tasks_and_constraints()
    return robot, model, c, h, q, v


def set_state(robot, q, v):
    """Set the state as TSID receives it (Pinocchio's q, v) with RobotModel.set_configuration."""
    robot.set_configuration(q, v)


def _set_refs(h, t):
    for key, (task, ref0, amp) in h.items():
        off = S.reference_offset(amp, t)
        if key == 'ee':
            T = ref0.copy()
            T[:3, 3] += off
            task.servo_controller().set_desired(T)
        else:
            task.set_desired(ref0 + off)


def _errors(h, robot):
    out = {}
    for key, (task, ref0, amp) in h.items():
        err = (
            task.servo_controller().get_cartesian_pose_error()[:3]
            if key == 'ee'
            else task.get_position_error()
        )
        out[key] = float(np.linalg.norm(err))
    return out


def run(name, n_steps=None, solver=None, capture=None):
    sc = S.SCENARIOS[name]
    robot, model, c, h, q, v = build(sc, solver)
    n = n_steps or S.steps(sc)
    times = np.empty(n)
    failures = 0
    gc.collect()
    gc.disable()
    for k in range(n):
        t = k * S.DT
        _set_refs(h, t)
        t0 = time.perf_counter()
        set_state(robot, q, v)
        ok = c.update(t, S.DT)
        tau = c.get_joint_torque_command()
        times[k] = time.perf_counter() - t0
        if not ok:
            failures += 1
        if capture is not None:
            buf = robot.buffers
            capture.append((buf.q_pin.copy(), buf.v_pin.copy(), c.get_problem_at_level(0)))
        dv = c.get_solution()[: model.nv]
        v = v + S.DT * dv
        q = pin.integrate(model, q, S.DT * v)
    gc.enable()
    p = c.get_problem_at_level(0)
    return {
        'impl': 'orca',
        'solver': c.solver.value,
        'scenario': name,
        **S.stats(times[min(100, n // 10):]),
        'failures': failures,
        'errors': _errors(h, robot),
        'nvar': int(p.layout.nx),
        'neq': int(p.n_eq),
        'nin': int(p.n_in),
        'tau_norm': float(np.linalg.norm(tau)),
    }


def capture(name, n_steps=None):
    """
    Run the scenario with the default solver and keep every cycle's QP (see qp_solvers.snapshot).

    Returns (the Pinocchio model, the controller, the captured cycles).
    """
    import qp_solvers

    sc = S.SCENARIOS[name]
    n = n_steps or S.steps(sc)
    robot, model, c, h, q, v = build(sc)
    cap = []
    for k in range(n):
        t = k * S.DT
        _set_refs(h, t)
        set_state(robot, q, v)
        c.update(t, S.DT)
        cap.append(qp_solvers.snapshot(c, robot))
        dv = c.get_solution()[: model.nv]
        v = v + S.DT * dv
        q = pin.integrate(model, q, S.DT * v)
    return model, c, cap


def floor(name, n_steps=None, solver=None):
    """
    Time the floor: computeAllTerms and one warm-started solve of each captured QP by ``solver``.

    The QPs are the controller's (default solver) of a first run, in solver units; ``solver``:
    daqp, proxqp, osqp (the controller's back-ends and settings) or piqp; None: the controller's
    default. Also reported: the solve alone, the solver's mean iterations, its failures and its
    largest deviation from the controller's solution (relative to max(1, |x|_inf)).
    """
    import qp_solvers

    model, c, cap = capture(name, n_steps)
    solver = solver or c.solver.value
    p = c.get_problem_at_level(0)
    nx, ne, ni = p.layout.nx, p.n_eq, p.n_in
    r = qp_solvers.time_floor(model, cap, solver, nx, ne, ni, p.layout.variable_scale)
    total, solve, iters = r['total'], r['solve'], r['iterations']
    n = len(cap)
    skip = min(100, n // 10)
    sol = S.stats(solve[skip:])
    return {
        'impl': f'floor_{solver}',
        'solver': solver,
        'default': solver == c.solver.value,
        'scenario': name,
        **S.stats(total[skip:]),
        'solve_median_us': sol['median_us'],
        'solve_p99_us': sol['p99_us'],
        'iterations_mean': float(np.mean(iters[skip:])),
        'failures': r['failures'],
        'max_rel_dev': r['max_rel_dev'],
        'nvar': int(nx),
        'neq': int(ne),
        'nin': int(ni),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('scenario', choices=sorted(S.SCENARIOS))
    ap.add_argument('--steps', type=int, default=None)
    ap.add_argument(
        '--solver',
        default=None,
        help="the controller's solver; with --floor, the floor's (or piqp); default: the default",
    )
    ap.add_argument('--floor', action='store_true')
    a = ap.parse_args()
    print(
        json.dumps(
            floor(a.scenario, a.steps, a.solver) if a.floor else run(a.scenario, a.steps, a.solver)
        )
    )


if __name__ == '__main__':
    main()
