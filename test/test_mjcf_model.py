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
Robots described in MJCF: ``RobotModel.load_model_from_file`` takes them (Pinocchio's parser).

The shipped arm written as MJCF (``mjcf/lwr.xml``, the URDF's numbers) is the same robot as its
URDF: mass matrix, nonlinear terms, torques, frames and limits at random states.
"""

import numpy as np
import orca_ros as orca
import pytest

# the terms compared are sums of a few dozen products of O(1) numbers, computed by the same
# algorithms on models whose numbers are identical: round-off, far below 1e-9
TOL = 1e-9


def _lwr_pair(floating=False):
    urdf, mjcf = orca.RobotModel(), orca.RobotModel()
    urdf.load_model_from_file(orca.default_urdf_path(), floating)
    mjcf.load_model_from_file(orca.share_path('mjcf', 'lwr.xml'), floating)
    return urdf, mjcf


def test_the_arm_as_mjcf_gives_the_torques_of_its_urdf(rng):
    urdf, mjcf = _lwr_pair()
    assert mjcf.get_joint_names() == urdf.get_joint_names()
    assert mjcf.mjcf_path.endswith('lwr.xml') and mjcf.urdf_xml is None
    for a, b in zip(mjcf.get_joint_position_limits(), urdf.get_joint_position_limits()):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(mjcf.get_joint_torque_limits(), urdf.get_joint_torque_limits())
    # MJCF has no velocity limits
    assert np.isinf(mjcf.get_joint_velocity_limits()).all()
    lo, hi = urdf.get_joint_position_limits()
    worst = 0.0
    for _ in range(100):
        q, v = rng.uniform(lo, hi), rng.uniform(-2.0, 2.0, 7)
        a = rng.uniform(-10.0, 10.0, 7)
        taus = []
        for robot in (urdf, mjcf):
            robot.set_robot_state(q, v)
            M = robot.get_mass_matrix()
            h = robot.get_generalized_gravity_and_coriolis_torques()
            taus.append((M, h, M @ a + h, robot.get_frame_pose('link_7')))
        for x, y in zip(*taus):
            worst = max(worst, float(np.abs(x - y).max()))
    print(f'largest difference over 100 states (M, h, M a + h, pose of link_7): {worst:.1e}')
    assert worst < TOL


def test_a_floating_arm_from_mjcf_and_a_free_joint(tmp_path, rng):
    """``floating_base`` adds the free flyer; a root ``freejoint`` is one (and asks for it)."""
    urdf, mjcf = _lwr_pair(floating=True)
    assert mjcf.get_nr_of_degrees_of_freedom() == 7 and mjcf.model.nv == 13
    T = np.eye(4)
    T[:3, 3] = [0.1, -0.2, 0.3]
    for _ in range(10):
        q, v = rng.uniform(-1.0, 1.0, 7), rng.uniform(-1.0, 1.0, 7)
        twist = rng.uniform(-1.0, 1.0, 6)
        terms = []
        for robot in (urdf, mjcf):
            robot.set_robot_state(T, q, twist, v, [0.0, 0.0, -9.81])
            terms.append((robot.get_mass_matrix(),
                          robot.get_generalized_gravity_and_coriolis_torques()))
        for x, y in zip(*terms):
            assert np.abs(x - y).max() < TOL
    text = open(orca.share_path('mjcf', 'lwr.xml')).read()
    free = tmp_path / 'free.xml'
    free.write_text(text.replace('<inertial pos="0 0 0" mass="0.1"',
                                 '<freejoint name="base"/><inertial pos="0 0 0" mass="0.1"', 1))
    robot = orca.RobotModel()
    robot.load_model_from_file(str(free), floating_base=True)
    assert robot.model.nv == 13 and robot.get_joint_names() == urdf.get_joint_names()
    with pytest.raises(ValueError, match="root body has a free joint \\('base'\\): load it "
                                         'with floating_base true'):
        orca.RobotModel().load_model_from_file(str(free))


def test_mjcf_the_parser_refuses_is_one_error_naming_it(tmp_path):
    bad = tmp_path / 'bad.xml'
    bad.write_text('<mujoco><worldbody><body name="a"><joint type="hinge"/>'
                   '<geom type="blob"/></body></worldbody></mujoco>')
    with pytest.raises(ValueError, match="could not parse MJCF '.*bad.xml': geomType does not "
                                         'exist'):
        orca.RobotModel().load_model_from_file(str(bad))
    ball = tmp_path / 'ball.xml'
    ball.write_text('<mujoco><worldbody><body name="a"><joint name="shoulder" type="ball"/>'
                    '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></worldbody>'
                    '</mujoco>')
    with pytest.raises(ValueError, match="joint 'shoulder' of type JointModelSpherical"):
        orca.RobotModel().load_model_from_file(str(ball))
    with pytest.raises(ValueError, match='MJCF text: give its file'):
        orca.RobotModel().load_model_from_string(bad.read_text())


def _mjcf_of(urdf: str, out) -> str:
    """Write ``urdf`` as MJCF the way MuJoCo converts it (its meshes by absolute path)."""
    import mujoco
    from orca_ros.robot.urdf_text import resolve_package_uris

    with open(urdf) as fh:
        spec = mujoco.MjSpec.from_string(resolve_package_uris(fh.read(), urdf))
    spec.compiler.fusestatic = False
    spec.compile()
    out.write_text(spec.to_xml())
    return str(out)


def test_a_robot_given_only_as_mjcf_with_meshes_reaches_its_targets_in_mujoco(tmp_path):
    """
    The iiwa of pybullet_data as MuJoCo writes it in MJCF (STL meshes), and nothing else.

    The shipped arm configuration, its frame and posture changed for this arm, built on the MJCF
    file; MuJoCo simulates the same file: three targets 10 cm apart, each within 1 mm.
    """
    import pybullet_data
    import yaml
    from orca_ros.configuration import build_from_config
    from orca_ros.sim.mujoco_server import MujocoServer

    path = _mjcf_of(f'{pybullet_data.getDataPath()}/kuka_iiwa/model.urdf', tmp_path / 'iiwa.xml')
    assert '.stl' in open(path).read() and '<robot' not in open(path).read()
    with open(orca.share_path('config', 'lwr_controller.yaml')) as fh:
        cfg = yaml.safe_load(fh)['orca_controller']['ros__parameters']
    q0 = [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]
    cfg.update(urdf_path=path, base_frame='lbr_iiwa_link_0', joints=[])
    cfg['tasks']['ee']['frame'] = 'lbr_iiwa_link_7'
    cfg['tasks']['posture']['target'] = q0
    setup = build_from_config(cfg)
    c, robot = setup.controller, setup.robot
    assert robot.mjcf_path == path and robot.get_nr_of_degrees_of_freedom() == 7
    for name, active in setup.initially_active.items():
        if active:
            (c.get_task(name) if name in setup.tasks else c.get_constraint(name)).activate()
    world = MujocoServer(ground_plane=False)
    arm = world.insert_model_from_urdf_file(path, fixed_base=True)
    names = robot.get_joint_names()
    jm = arm.joint_map(names)
    arm.set_model_configuration(names, q0)
    servo = setup.tasks['ee'].servo_controller()
    dt, t = 1e-3, 0.0
    robot.set_robot_state(arm.get_joint_positions(jm), arm.get_joint_velocities(jm))
    start = robot.get_frame_pose('lbr_iiwa_link_7')
    errors = []
    for offset in ([0.1, 0.0, 0.0], [0.1, -0.1, 0.0], [0.0, -0.1, -0.1]):
        target = start.copy()
        target[:3, 3] += offset
        servo.set_desired(target)
        for _ in range(4000):
            robot.set_robot_state(arm.get_joint_positions(jm), arm.get_joint_velocities(jm))
            assert c.update(t, dt)
            arm.set_joint_torque_command(c.get_joint_torque_command(), jm)
            world.step()
            t += dt
        robot.set_robot_state(arm.get_joint_positions(jm), arm.get_joint_velocities(jm))
        errors.append(np.linalg.norm(robot.get_frame_pose('lbr_iiwa_link_7')[:3, 3]
                                     - target[:3, 3]))
    print('final errors [m]:', ', '.join(f'{e:.1e}' for e in errors))
    assert max(errors) < 1e-3
