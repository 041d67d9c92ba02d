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
Quadrupeds this project was not tuned on, in PyBullet, with default settings (issue 11).

Solo12 (2.5 kg), Go1 (13 kg) and ANYmal C (52 kg) from example-robot-data stand on four point
contacts in their SRDF's standing pose and sway their CoM +-3 cm sideways at 0.5 Hz: the CoM task,
the regularisation, the contacts (friction 0.8) and the torque / position / velocity limits all
keep their defaults, the posture weighs 1e-3. The scaled defaults must hold across a 20x range of
mass.
"""

import numpy as np
import orca_ros as orca
from orca_ros.sim import resolve_package_uris, SimServer
import pytest

DT = 0.001
AMPLITUDE = 0.03
OMEGA = np.pi  # 0.5 Hz
# robot: (URDF, SRDF, feet, height of a foot frame over the ground when its foot touches it)
ROBOTS = {
    # foot: convex hull of a 16 mm ball mesh centred on the frame
    'solo12': (
        'solo_description/robots/solo12.urdf',
        'solo_description/srdf/solo.srdf',
        ('FL_FOOT', 'FR_FOOT', 'HL_FOOT', 'HR_FOOT'),
        0.016,
    ),
    # foot: a 20 mm sphere centred on the frame
    'go1': (
        'go1_description/urdf/go1.urdf',
        'go1_description/srdf/go1.srdf',
        ('FL_foot', 'FR_foot', 'RL_foot', 'RR_foot'),
        0.02,
    ),
    # foot: a 30 mm sphere centred 22.5 mm above the frame
    'anymal_c': (
        'anymal_c_simple_description/urdf/anymal.urdf',
        'anymal_c_simple_description/srdf/anymal.srdf',
        ('LF_FOOT', 'RF_FOOT', 'LH_FOOT', 'RH_FOOT'),
        0.0075,
    ),
}


def _standing(example_robot_urdf, which):
    import pinocchio as pin

    urdf, srdf, feet, foot_height = ROBOTS[which]
    urdf = example_robot_urdf(urdf)
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf, floating_base=True)
    model = robot.model
    pin.loadReferenceConfigurations(model, example_robot_urdf(srdf), False)
    q = np.array(model.referenceConfigurations['standing'])
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    q[2] += foot_height - min(data.oMf[model.getFrameId(f)].translation[2] for f in feet)
    robot.set_base_frame('world')
    robot.set_configuration(q, np.zeros(model.nv))
    return robot, q, urdf, feet


@pytest.mark.parametrize('which', sorted(ROBOTS))
def test_a_quadruped_sways_its_com_with_default_settings(
    example_robot_urdf, com_sway_in_pybullet, tmp_path, which
):
    robot, q, urdf, feet = _standing(example_robot_urdf, which)
    c = orca.Controller(which, robot)
    for f in feet:
        contact = c.add_constraint(orca.Contact(f'{f}_contact', f))
        contact.set_friction_coefficient(0.8)
        contact.set_ramp_duration(0.0)  # standing from the first cycle
    com = c.add_task(orca.CoMTask, 'com')
    posture = c.add_task(orca.JointAccelerationTask, 'posture')
    posture.set_weight(1e-3)
    posture.set_desired(robot.get_joint_positions())
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position_limit')
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity_limit')
    c.activate_tasks_and_constraints()
    path = tmp_path / f'{which}.urdf'
    with open(urdf) as f:
        path.write_text(resolve_package_uris(f.read(), urdf))
    names = robot.get_joint_names()
    limits = robot.get_joint_torque_limits()  # the URDF's efforts
    with SimServer(time_step=DT) as server:
        sim = server.insert_model_from_urdf_file(
            str(path), position=q[:3], orientation=q[3:7], fixed_base=False
        )
        by_name = sim.joint_map(names)
        sim.set_model_configuration(names, q[7:])
        feet0, over, slide = [], [], [0.0]

        def after_step(k, torques):
            over.append(float(np.max(np.abs(torques) - limits)))
            at = np.array([sim.get_link_position(f)[:2] for f in feet])
            if k == 100:  # settled on the ground
                feet0.append(at)
            if feet0:
                slide[0] = max(slide[0], float(np.linalg.norm(at - feet0[0], axis=1).max()))

        errors, failures = com_sway_in_pybullet(
            robot, c, com, server, sim, by_name, 4.0, AMPLITUDE, OMEGA, after_step
        )
        height = sim.get_world_to_base_transform()[2, 3]
    rms = float(np.sqrt(np.mean(np.square(errors))))
    assert failures == 0
    assert max(over) <= 1e-9  # torques within the URDF's efforts
    assert rms <= 0.005, f'CoM rms error {1000 * rms:.2f} mm'
    assert slide[0] <= 0.005, f'a foot slid {1000 * slide[0]:.1f} mm'
    assert abs(height - q[2]) < 0.01  # standing at its height
