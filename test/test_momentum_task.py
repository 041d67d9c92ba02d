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
The centroidal momentum task (MomentumTask): its terms, and Talos pushed in PyBullet.

A_g and its drift are checked against finite differences of h = A_g nu along trajectories; the
push: 100 N for 0.1 s at the torso of Talos standing on two soles (the default settings of
test_talos_balance's controller), with and without an angular momentum task.
"""

import numpy as np
import orca_ros as orca
from orca_ros.sim import SimServer
import pinocchio as pin
from test_talos_balance import _talos, CORNERS, DT, SOLES
from test_talos_pybullet import _talos_urdf_for_pybullet


def test_momentum_and_its_drift_match_finite_differences_on_talos(example_robot_urdf):
    """
    h_dot = A_g nu_dot + A_g_dot nu against central differences of h along q(t), nu(t).

    Random states and accelerations of the floating Talos; q(t +- e) integrated with nu e +
    nu_dot e^2 / 2, nu(t +- e) = nu +- nu_dot e (Pinocchio's convention of the base's velocity).
    The linear part is m v_com (Pinocchio's CoM Jacobian).
    """
    robot = orca.RobotModel()
    robot.load_model_from_file(
        example_robot_urdf('talos_data/robots/talos_reduced.urdf'), floating_base=True
    )
    model = robot.model
    mass = robot.get_total_mass()
    rng = np.random.default_rng(2)
    eps = 1e-4
    worst = 0.0
    for _ in range(20):
        q = pin.integrate(model, pin.neutral(model), rng.normal(0.0, 0.5, model.nv))
        v, a = rng.normal(0.0, 1.0, model.nv), rng.normal(0.0, 1.0, model.nv)
        robot.set_configuration(q, v)
        h, Ag, drift = (x.copy() for x in robot.get_centroidal_momentum_terms())
        np.testing.assert_allclose(h[:3], mass * pin.jacobianCenterOfMass(model,
                                   model.createData(), q) @ v, rtol=0, atol=1e-9)
        hs = []
        for s in (1.0, -1.0):
            robot.set_configuration(
                pin.integrate(model, q, s * eps * v + 0.5 * eps**2 * a), v + s * eps * a
            )
            hs.append(robot.get_centroidal_momentum_terms()[0].copy())
        fd = (hs[0] - hs[1]) / (2.0 * eps)
        rate = Ag @ a + drift
        worst = max(worst, np.abs(fd - rate).max() / max(1.0, np.abs(rate).max()))
    print(f'h_dot: A_g a + drift vs finite differences {worst:.1e} (relative)')
    assert worst <= 1e-6


def test_the_task_sets_the_momentum_rate(talos_standing):
    """
    Talos on its two soles, the task alone: the solved h_dot is the servo's (default Kp 10 1/s).

    The soles' wrenches change the momentum (without contacts only gravity would: the dynamics
    leave h_dot = m g whatever the task asks).
    """
    robot, q = talos_standing()
    model = robot.model
    v = np.random.default_rng(4).normal(0.0, 0.05, model.nv)
    robot.set_configuration(q, v)
    c = orca.Controller('c', robot)
    for f in SOLES:
        c.add_constraint(orca.SurfaceContact(f, f, CORNERS, friction_coefficient=0.3))
    task = c.add_task(orca.MomentumTask, 'momentum')
    task.set_weight(1e3)  # above the regularisation's (at the default 1: within ~20 %)
    ref = np.array([0.0, 0.0, 0.0, 0.5, -0.5, 0.2])
    task.set_desired(momentum=ref)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, DT), c.get_return_code()
    h, Ag, drift = robot.get_centroidal_momentum_terms()
    nu_dot = c.get_solution()[: model.nv]
    expected = 10.0 * (ref - h)
    rate = Ag @ nu_dot + drift
    print(f'h_dot {rate} for {expected}')
    np.testing.assert_allclose(rate, expected, rtol=0, atol=1e-3 * np.abs(expected).max())
    # by the compiled cycle's kernel (its terms the robot's, as the reference path's)
    assert 'momentum' in {low.obj.name for low in c.compiled_cycle.lowered}


def _push_run(talos_standing, example_robot_urdf, tmp_path, com_sway_in_pybullet, with_task):
    """Talos standing in PyBullet, pushed 100 N for 0.1 s at the torso; |L| along the way."""
    robot, c, com, q = _talos(talos_standing, 'daqp')
    if with_task:
        am = c.add_task(orca.MomentumTask, 'angular_momentum')
        am.set_selection_vector([0, 0, 0, 1, 1, 1])
        am.activate()
    urdf = _talos_urdf_for_pybullet(example_robot_urdf, tmp_path / 'talos.urdf')
    names = robot.get_joint_names()
    peak = [0.0]
    with SimServer(time_step=DT) as server:
        sim = server.insert_model_from_urdf_file(
            urdf, position=q[:3], orientation=q[3:7], fixed_base=False
        )
        sim.set_model_configuration(names, q[7:])

        def after_step(k, torques):
            # the state of cycle k is still the robot's: its angular momentum
            peak[0] = max(peak[0], np.linalg.norm(robot.get_centroidal_momentum_terms()[0][3:]))
            if 499 <= k < 599:  # steps 500-599: 0.5 s standing, then 100 N along x for 0.1 s
                sim.apply_external_force('torso_2_link', [100.0, 0.0, 0.0])

        # standing: the CoM held where it starts (no sway)
        _, failures = com_sway_in_pybullet(robot, c, com, server, sim, sim.joint_map(names),
                                           2.0, 0.0, 0.0, after_step)
        base_height = sim.get_world_to_base_transform()[2, 3]
    return peak[0], failures, base_height - q[2]


def test_an_angular_momentum_task_damps_a_push_on_talos(
    talos_standing, example_robot_urdf, tmp_path, com_sway_in_pybullet
):
    """
    The push of 10 N s at the torso, with and without the task (angular part, defaults).

    With it: no QP failure, no fall, and a lower peak of the angular momentum about the CoM.
    """
    out = {
        flag: _push_run(talos_standing, example_robot_urdf, tmp_path, com_sway_in_pybullet, flag)
        for flag in (False, True)
    }
    for flag, (peak, failures, drop) in out.items():
        print(f'momentum task {flag}: peak |L| {peak:.3f} N m s, failures {failures}, '
              f'base {drop:+.3f} m')
    peak, failures, drop = out[True]
    assert failures == 0
    assert drop > -0.15  # standing: a fall drops the base ~1 m
    assert peak < out[False][0], out


def test_momentum_task_from_yaml():
    """The shipped quadruped configuration with an angular momentum task (type: momentum)."""
    from orca_ros.configuration.controller_builder import build_from_config, ConfigError
    from orca_ros.examples.quadruped import STAND_HEIGHT, STAND_Q
    import pytest
    import yaml

    with open(orca.share_path('config', 'quadruped_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    tasks = cfg['tasks']
    tasks['names'].append('am')
    tasks['am'] = {'type': 'momentum', 'selection': [0, 0, 0, 1, 1, 1], 'kp': 5.0,
                   'target': [0.0] * 6, 'weight': 0.5}
    setup = build_from_config(cfg)
    am = setup.controller.get_task('am')
    assert isinstance(am, orca.MomentumTask)
    np.testing.assert_array_equal(am.pid().get_proportional_gain(), [5.0] * 6)
    np.testing.assert_array_equal(am.get_selection_vector(), [0, 0, 0, 1, 1, 1])
    T = np.eye(4)
    T[2, 3] = STAND_HEIGHT
    setup.robot.set_robot_state(T, STAND_Q, np.zeros(6), np.zeros(12), [0.0, 0.0, -9.81])
    setup.controller.activate_tasks_and_constraints()
    for k in range(50):
        assert setup.controller.update(k * 0.001, 0.001)
    tasks['am']['target'] = [0.0] * 5
    with pytest.raises(ConfigError, match='am.target'):
        build_from_config(cfg)
