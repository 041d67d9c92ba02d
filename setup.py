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
ament_python package.

Installs the Python package, the URDFs and YAML configs under share/orca_ros.
"""

import glob
import os

from setuptools import find_packages, setup

PACKAGE = 'orca_ros'


def data(pattern):
    return [f for f in glob.glob(pattern) if os.path.isfile(f)]


setup(
    name=PACKAGE,
    version='0.1.0',
    packages=find_packages(include=[PACKAGE, f'{PACKAGE}.*']),
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{PACKAGE}']),
        (f'share/{PACKAGE}', ['package.xml']),
        (f'share/{PACKAGE}/urdf', data('urdf/*')),
        (f'share/{PACKAGE}/mjcf', data('mjcf/*')),
        (f'share/{PACKAGE}/config', data('config/*')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='orca_ros developers',
    maintainer_email='dev@orca-ros.invalid',
    description='Whole-body reactive QP controller with ROS 2 nodes and a PyBullet bridge',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'orca_simple_controller = orca_ros.examples.simple_controller:main',
            'orca_simulating_results = orca_ros.examples.simulating_results:main',
            'orca_using_callbacks = orca_ros.examples.using_callbacks:main',
            'orca_using_lambda_callbacks = orca_ros.examples.using_lambda_callbacks:main',
            'orca_plotting_torques = orca_ros.examples.plotting_torques:main',
            'orca_sim_single_robot = orca_ros.examples.sim_single_robot:main',
            'orca_sim_multiple_robots = orca_ros.examples.sim_multiple_robots:main',
            'orca_sim_gravity_compensation = orca_ros.examples.sim_gravity_compensation:main',
            'orca_sim_controller_in_the_loop = orca_ros.examples.sim_controller_in_the_loop:main',
            'orca_closed_loop_demo = orca_ros.examples.closed_loop_demo:main',
            'orca_main_job = orca_ros.ros.main_job:main',
            'bag_recorder = orca_ros.ros.bag_recorder:main',
            'plot = orca_ros.recording.plot_command:main',
            'orca_controller = orca_ros.ros.controller_node:main',
            'pybullet_bridge = orca_ros.ros.pybullet_bridge:main',
            'mujoco_bridge = orca_ros.ros.mujoco_bridge:main',
            'web_view = orca_ros.ros.web_view:main',
        ],
    },
)
