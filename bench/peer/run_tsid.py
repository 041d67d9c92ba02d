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
One scenario of scenarios.py run with TSID (the peer); prints one JSON line.

Runs in the benchmark's side venv (Python 3.13, `tsid` wheel): see bench/tsid_venv.sh. Timed per
step: what a controller does between a new state and its torques -- computeProblemData (Pinocchio's
computeAllTerms and every task/constraint/contact) + the HQP solve (eiquadprog) + reading torques
and accelerations.

Usage: python run_tsid.py SCENARIO [--steps N]
"""

from __future__ import annotations

import gc
import time
import warnings

import numpy as np

warnings.filterwarnings('ignore')
import pinocchio as pin  # noqa: E402
import scenarios as S  # noqa: E402
import tsid  # noqa: E402


def _se3_sample(H: pin.SE3):
    s = tsid.TrajectorySample(12, 6)
    v = np.zeros(12)
    v[:3] = H.translation
    v[3:] = H.rotation.reshape(-1, order='F')
    s.value(v)
    return s


def _vec_sample(p):
    s = tsid.TrajectorySample(len(p))
    s.value(np.asarray(p, float))
    return s


def build(sc):
    path = S.urdf_path(sc)
    if sc['floating']:
        robot = tsid.RobotWrapper(path, [], pin.JointModelFreeFlyer(), False)
    else:
        robot = tsid.RobotWrapper(path, [], False)
    model = robot.model()
    q = S.initial_configuration(sc, model)
    v = np.zeros(model.nv)
    form = tsid.InverseDynamicsFormulationAccForce('tsid', robot, False)
    form.computeProblemData(0.0, q, v)
    data = form.data()
    h = {}
    # TSID's bindings do not keep tasks and contacts alive: the formulation only holds references
    keep = []
    if 'ee' in sc:
        e = sc['ee']
        task = tsid.TaskSE3Equality('ee', robot, e['frame'])
        task.setKp(np.full(6, 1.0) * e['kp'])
        task.setKd(np.full(6, 1.0) * e['kd'])
        task.useLocalFrame(False)
        form.addMotionTask(task, e['weight'], 1, 0.0)
        keep.append(task)
        H0 = robot.framePosition(data, model.getFrameId(e['frame']))
        h['ee'] = (task, H0.copy(), e['amplitude'])
    if 'com' in sc:
        e = sc['com']
        task = tsid.TaskComEquality('com', robot)
        task.setKp(np.full(3, e['kp']))
        task.setKd(np.full(3, e['kd']))
        form.addMotionTask(task, e['weight'], 1, 0.0)
        keep.append(task)
        h['com'] = (task, robot.com(data).copy(), e['amplitude'])
    p = sc['posture']
    post = tsid.TaskJointPosture('posture', robot)
    post.setKp(np.full(robot.na, p['kp']))
    post.setKd(np.full(robot.na, p['kd']))
    post.setReference(_vec_sample(q[-robot.na:]))
    form.addMotionTask(post, p['weight'], 1, 0.0)
    keep.append(post)
    if 'points' in sc:
        c = sc['points']
        for f in c['frames']:
            ct = tsid.ContactPoint(
                f, robot, f, np.array([0.0, 0.0, 1.0]), c['mu'], c['fmin'], c['fmax']
            )
            ct.setKp(np.zeros(3))
            ct.setKd(np.zeros(3))
            ct.useLocalFrame(False)
            ct.setReference(robot.framePosition(data, model.getFrameId(f)))
            form.addRigidContact(ct, 1e-5)
            keep.append(ct)
    if 'soles' in sc:
        c = sc['soles']
        corners = S.sole_corners(sc).T.copy()
        for f in c['frames']:
            ct = tsid.Contact6d(
                f, robot, f, corners, np.array([0.0, 0.0, 1.0]), c['mu'], c['fmin'], c['fmax']
            )
            ct.setKp(np.zeros(6))
            ct.setKd(np.zeros(6))
            ct.setReference(robot.framePosition(data, model.getFrameId(f)))
            form.addRigidContact(ct, 1e-5)
            keep.append(ct)
    na = robot.na
    if 'torque' in sc['limits']:
        tb = tsid.TaskActuationBounds('torque', robot)
        e = model.effortLimit[-na:]
        tb.setBounds(-e, e)
        form.addActuationTask(tb, 1.0, 0, 0.0)
        keep.append(tb)
    if 'position' in sc['limits'] or 'velocity' in sc['limits']:
        jb = tsid.TaskJointPosVelAccBounds('bounds', robot, S.DT, False)
        jb.setPositionBounds(model.lowerPositionLimit[-na:], model.upperPositionLimit[-na:])
        jb.setVelocityBounds(model.velocityLimit[-na:])
        jb.setAccelerationBounds(np.full(na, 1e4))
        form.addMotionTask(jb, 1.0, 0, 0.0)
        keep.append(jb)
    solver = tsid.SolverHQuadProgFast('qp')
    solver.resize(form.nVar, form.nEq, form.nIn)
    return robot, model, form, solver, h, q, v, keep


def _set_refs(h, t):
    for key, (task, ref0, amp) in h.items():
        off = S.reference_offset(amp, t)
        if key == 'ee':
            H = ref0.copy()
            H.translation = ref0.translation + off
            task.setReference(_se3_sample(H))
        else:
            task.setReference(_vec_sample(ref0 + off))


def _errors(h, robot, data):
    out = {}
    for key, (task, ref0, amp) in h.items():
        out[key] = float(np.linalg.norm(task.position_error[:3]))
    return out


def run(name: str, n_steps: int | None):
    sc = S.SCENARIOS[name]
    robot, model, form, solver, h, q, v, _keep = build(sc)
    n = n_steps or S.steps(sc)
    times = np.empty(n)
    failures = 0
    gc.collect()
    gc.disable()
    for k in range(n):
        t = k * S.DT
        _set_refs(h, t)
        t0 = time.perf_counter()
        hqp = form.computeProblemData(t, q, v)
        sol = solver.solve(hqp)
        tau = form.getActuatorForces(sol)
        dv = form.getAccelerations(sol)
        times[k] = time.perf_counter() - t0
        if sol.status != 0:
            failures += 1
        v = v + S.DT * dv
        q = pin.integrate(model, q, S.DT * v)
    gc.enable()
    err = _errors(h, robot, form.data())
    return {
        'impl': 'tsid',
        'scenario': name,
        **S.stats(times[min(100, n // 10):]),
        'failures': failures,
        'errors': err,
        'nvar': form.nVar,
        'neq': form.nEq,
        'nin': form.nIn,
        'tau_norm': float(np.linalg.norm(tau)),
    }


if __name__ == '__main__':
    S.cli(run)
