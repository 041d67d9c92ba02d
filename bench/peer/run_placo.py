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
One scenario of scenarios.py run with PlaCo's DynamicsSolver (second peer); prints one JSON line.

Runs in the benchmark's side venv of PlaCo (`placo` wheel and its own Pinocchio): see
bench/placo_venv.sh. Timed per step: what a controller does between a new state and its torques --
writing q and v into the RobotWrapper's state, update_kinematics (frame placements, joint
Jacobians and their time variation) + DynamicsSolver.solve (mass matrix, nonlinear effects, every
task/contact/limit, eiquadprog) + reading torques and accelerations.

How the scenarios map onto PlaCo:

- PlaCo's RobotWrapper always has a floating base; the fixed-base Panda masks it
  (mask_fbase: zero base acceleration, free base wrench). The state is kept in PlaCo's layout.
- The 6-D end-effector task is a frame task: a position task and an orientation task, each
  with one scalar kp/kd (the scenarios' per-axis gains are uniform per 3-D block) and the
  scenario's weight on both. Both use world-aligned Jacobians, like TSID's SE3 task.
- The posture is a joints task on every actuated joint (target: the start configuration).
- PlaCo regularizes the actuated torques by default (torque_cost 1e-3 * |tau|^2). That term is
  in none of the scenarios (TSID and orca_ros have no such cost) and it changes the physics: with
  it, Talos's CoM error is ~16 times TSID's (the Panda's and the quadruped's barely move). It is
  set to 0.
- Limits: torque (|tau| <= URDF effort), velocity (|v + dt dv| <= URDF velocity) and joint
  limits. PlaCo's joint limits are its own formulation (the velocity towards a limit is kept
  below sqrt(2 qdd_safe d)), not TSID's viability bounds; qdd_safe is left at its default (1).
- Point contacts (quadruped): a hard position task per foot with kp = kd = 0 (zero contact
  acceleration, as TSID's contacts with zero gains) and a unilateral point contact (4-face
  pyramid, world z normal). Forces are regularized as TSID does (1e-5 on the tangential forces,
  TSID's 1e-8 relative weight on f_z dropped). PlaCo has no maximum normal force: fmax is not
  expressed (it does not bind).
- Sole contacts (Talos): a hard frame task per sole with kp = kd = 0 and a planar contact. PlaCo
  models it with one 6-D wrench in the sole frame (f_z >= 0, CoP in the rectangle, linearized
  friction on the resultant force), not with forces at the 4 corners as TSID and orca_ros do:
  no torsional friction limit, no maximum normal force. The moments are regularized as TSID
  does (1e-5 * 2^2); TSID's 1e-5 on the tangential forces is not reproduced (PlaCo's
  weight_tangentials of a planar contact also weighs f_z, which TSID leaves nearly free).

Usage: python run_placo.py SCENARIO [--steps N]
"""

from __future__ import annotations

import gc
import os
import time
import warnings

import numpy as np

warnings.filterwarnings('ignore')
import pinocchio as pin  # noqa: E402
import placo  # noqa: E402
import scenarios as S  # noqa: E402


def _load_robot(path: str):
    """
    Load a URDF file into PlaCo's RobotWrapper.

    PlaCo also builds the URDF's geometry: its meshes' package:// paths are resolved through
    ROS_PACKAGE_PATH, set here to the example-robot-data share directory when the file is there.
    """
    marker = os.sep + 'example-robot-data' + os.sep
    if marker in path:
        share = path.split(marker)[0]
        old = os.environ.get('ROS_PACKAGE_PATH')
        os.environ['ROS_PACKAGE_PATH'] = share if not old else share + os.pathsep + old
    return placo.RobotWrapper(path, placo.Flags.ignore_collisions)


def _gain(g, block: int) -> float:
    """Return the scalar gain of a 3-D block of a scalar or 6-vector gain (uniform blocks only)."""
    g = np.broadcast_to(np.asarray(g, float), (6,))[3 * block:3 * block + 3]
    if not np.all(g == g[0]):
        raise ValueError('PlaCo tasks have one scalar gain per 3-D block')
    return float(g[0])


def _set_gains(task, kp: float, kd: float):
    task.kp = kp
    task.kd = kd  # >= 0: used as given (negative would mean PlaCo's critical damping)


def build(sc):
    robot = _load_robot(S.urdf_path(sc))
    model = robot.model
    solver = placo.DynamicsSolver(robot)
    solver.dt = S.DT
    solver.torque_cost = 0.0
    if sc['floating']:
        q = S.initial_configuration(sc, model)
    else:
        solver.mask_fbase(True)
        q = np.concatenate(([0.0] * 6 + [1.0], S.initial_configuration(sc, model)))
    v = np.zeros(model.nv)
    robot.state.q = q
    robot.state.qd = v
    robot.update_kinematics()
    joints = list(robot.joint_names())
    h = {}
    keep = []
    if 'ee' in sc:
        e = sc['ee']
        T0 = robot.get_T_world_frame(e['frame']).copy()
        task = solver.add_frame_task(e['frame'], T0)
        task.configure('ee', 'soft', e['weight'], e['weight'])
        _set_gains(task.position(), _gain(e['kp'], 0), _gain(e['kd'], 0))
        _set_gains(task.orientation(), _gain(e['kp'], 1), _gain(e['kd'], 1))
        keep.append(task)
        h['ee'] = (task, T0, e['amplitude'])
    if 'com' in sc:
        e = sc['com']
        c0 = robot.com_world().copy()
        task = solver.add_com_task(c0)
        task.configure('com', 'soft', e['weight'])
        _set_gains(task, e['kp'], e['kd'])
        keep.append(task)
        h['com'] = (task, c0, e['amplitude'])
    p = sc['posture']
    post = solver.add_joints_task()
    post.set_joints({j: robot.get_joint(j) for j in joints})
    post.configure('posture', 'soft', p['weight'])
    _set_gains(post, p['kp'], p['kd'])
    keep.append(post)
    if 'points' in sc:
        c = sc['points']
        for f in c['frames']:
            pt = solver.add_position_task(f, robot.get_T_world_frame(f)[:3, 3].copy())
            pt.configure(f, 'hard', 1.0)
            _set_gains(pt, 0.0, 0.0)
            ct = solver.add_unilateral_point_contact(pt)
            ct.mu = c['mu']
            ct.weight_tangentials = 1e-5
            keep += [pt, ct]
    if 'soles' in sc:
        c = sc['soles']
        for f in c['frames']:
            ft = solver.add_frame_task(f, robot.get_T_world_frame(f).copy())
            ft.configure(f, 'hard', 1.0, 1.0)
            _set_gains(ft.position(), 0.0, 0.0)
            _set_gains(ft.orientation(), 0.0, 0.0)
            ct = solver.add_planar_contact(ft)
            ct.mu = c['mu']
            ct.length = 2.0 * c['half_length']
            ct.width = 2.0 * c['half_width']
            ct.weight_moments = 4e-5
            keep += [ft, ct]
    solver.enable_torque_limits('torque' in sc['limits'])
    solver.enable_joint_limits('position' in sc['limits'])
    solver.enable_velocity_limits('velocity' in sc['limits'])
    return robot, model, solver, h, q, v, keep


def _set_refs(h, t):
    for key, (task, ref0, amp) in h.items():
        off = S.reference_offset(amp, t)
        if key == 'ee':
            T = ref0.copy()
            T[:3, 3] += off
            task.T_world_frame = T
        else:
            task.target_world = ref0 + off


def _errors(h):
    out = {}
    for key, (task, ref0, amp) in h.items():
        err = task.position().error if key == 'ee' else task.error
        out[key] = float(np.linalg.norm(np.asarray(err).ravel()[:3]))
    return out


def run(name: str, n_steps: int | None):
    sc = S.SCENARIOS[name]
    robot, model, solver, h, q, v, _keep = build(sc)
    n = n_steps or S.steps(sc)
    times = np.empty(n)
    failures = 0
    state = robot.state
    gc.collect()
    gc.disable()
    for k in range(n):
        t = k * S.DT
        _set_refs(h, t)
        t0 = time.perf_counter()
        state.q = q
        state.qd = v
        robot.update_kinematics()
        res = solver.solve(False)
        tau = res.tau[6:]
        dv = res.qdd
        times[k] = time.perf_counter() - t0
        if not res.success:
            failures += 1
            dv = np.zeros(model.nv)
        v = v + S.DT * dv
        q = pin.integrate(model, q, S.DT * v)
    gc.enable()
    # PlaCo eliminates the hard equalities (and the masked floating base) before its QP
    pb = solver.problem
    return {
        'impl': 'placo',
        'scenario': name,
        **S.stats(times[min(100, n // 10):]),
        'failures': failures,
        'errors': _errors(h),
        'nvar': int(pb.n_variables),
        'neq': int(pb.determined_variables + pb.fixed_variables + pb.n_equalities),
        'nin': int(pb.n_inequalities),
        'tau_norm': float(np.linalg.norm(tau)),
    }


if __name__ == '__main__':
    S.cli(run)
