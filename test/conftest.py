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
import importlib.util
import os

import numpy as np
import orca_ros as orca
import pytest

# the core's tests run without ROS; the nodes' tests (and the colcon build) need rclpy
collect_ignore_glob = []
if importlib.util.find_spec('rclpy') is None:
    collect_ignore_glob += ['test_ros_*.py', 'test_colcon_package.py']
if importlib.util.find_spec('colcon_core') is None:
    collect_ignore_glob += ['test_colcon_package.py']


_REAL_TIME_BUDGET = orca.Controller.default_time_budget


@pytest.fixture(autouse=True, scope='session')
def offline_solve_budget():
    """
    Give the core's offline runs a 10 s wall-clock budget per cycle, for the whole session.

    The default budget (one 1 ms control period of wall-clock time, turned into solver iterations)
    bounds a real-time loop; tests judging physics must not depend on the machine's load (two CPU
    burners beside the suite cut 1 ms cycles short, and even 0.1 s was preempted at a load of 9
    on 2 cores). Session scope: module-scoped fixtures (the quadruped's 19 s run) are set up
    before any function-scoped fixture, and ran with the real-time budget when this was one.
    """
    patch = pytest.MonkeyPatch()
    patch.setattr(orca.Controller, 'default_time_budget', 10.0)
    yield
    patch.undo()


@pytest.fixture(autouse=True)
def real_time_budget(request, monkeypatch):
    """Restore the real-time budget for a test about it (``@pytest.mark.real_time_budget``)."""
    if request.node.get_closest_marker('real_time_budget') is not None:
        monkeypatch.setattr(orca.Controller, 'default_time_budget', _REAL_TIME_BUDGET)


@pytest.fixture(scope='session')
def lwr_urdf():
    return orca.default_urdf_path()


@pytest.fixture(scope='session')
def iiwa_urdf():
    import pybullet_data

    return os.path.join(pybullet_data.getDataPath(), 'kuka_iiwa', 'model.urdf')


@pytest.fixture(scope='session')
def example_robot_urdf():
    """Path of a URDF of example-robot-data, e.g. ``talos_data/robots/talos_reduced.urdf``."""
    import glob
    import sys

    def find(rel):
        for p in sys.path:
            hit = glob.glob(f'{p}/cmeel.prefix/share/example-robot-data/robots/{rel}')
            if hit:
                return hit[0]
        pytest.skip('example-robot-data not installed')

    return find


@pytest.fixture(scope='session')
def talos_standing(example_robot_urdf):
    """Make Talos (talos_reduced, floating base) in half-sitting, soles on z = 0: (robot, q)."""
    import orca_ros as orca
    import pinocchio as pin

    def make():
        robot = orca.RobotModel()
        robot.load_model_from_file(
            example_robot_urdf('talos_data/robots/talos_reduced.urdf'), floating_base=True
        )
        model = robot.model
        srdf = example_robot_urdf('talos_data/srdf/talos.srdf')
        pin.loadReferenceConfigurations(model, srdf, False)
        q = np.array(model.referenceConfigurations['half_sitting'])
        data = model.createData()
        pin.framesForwardKinematics(model, data, q)
        soles = ('leg_left_sole_fix_joint', 'leg_right_sole_fix_joint')
        q[2] -= min(data.oMf[model.getFrameId(f)].translation[2] for f in soles)
        robot.set_base_frame('world')
        robot.set_configuration(q, np.zeros(model.nv))
        return robot, q

    return make


@pytest.fixture(scope='session')
def com_sway_in_pybullet():
    """
    Close a controller on a floating-base robot in PyBullet while its CoM task sways sideways.

    ``run(robot, controller, com_task, server, sim, by_name, seconds, amplitude, omega,
    after_step=None)``: the CoM target moves by amplitude sin(omega t) along y from where the CoM
    starts; ``after_step(k, torques)`` is called after each simulation step. Returns the CoM
    errors (one per cycle) and the number of failed cycles.
    """

    def run(robot, c, com, server, sim, by_name, seconds, amplitude, omega, after_step=None):
        gravity = np.array([0.0, 0.0, -9.81])
        dt = server.time_step
        errors, failures, c0 = [], 0, None
        for k in range(int(round(seconds / dt))):
            t = k * dt
            robot.set_robot_state(
                sim.get_world_to_base_transform(),
                sim.get_joint_positions(by_name),
                sim.get_base_velocity(),
                sim.get_joint_velocities(by_name),
                gravity,
            )
            if c0 is None:
                c0 = robot.get_center_of_mass()
            s, co = np.sin(omega * t), np.cos(omega * t)
            ref = c0 + [0.0, amplitude * s, 0.0]
            com.set_desired(
                ref, [0.0, amplitude * omega * co, 0.0], [0.0, -amplitude * omega**2 * s, 0.0]
            )
            errors.append(np.linalg.norm(robot.get_center_of_mass() - ref))
            failures += not c.update(t, dt)
            torques = c.get_joint_torque_command()
            sim.set_joint_torque_command(torques, by_name)
            server.step()
            if after_step is not None:
                after_step(k, torques)
        return np.array(errors), failures

    return run


@pytest.fixture
def rng():
    return np.random.default_rng(1234)
