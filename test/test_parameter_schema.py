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
"""The run-time parameter schema: validation reasons, and the docs' table generated from it."""

import os

from orca_ros.ros.parameter_schema import markdown, ParamRejected, validate
import pytest

TASKS, CONSTRAINTS = ('ee', 'posture'), ('torque_limit',)


@pytest.mark.parametrize(
    'name,value,reason',
    [
        ('solver', 'banana', 'read-only at run time'),
        ('update_rate', 0.0, 'read-only at run time'),
        ('tasks.ee.type', 'com', 'read-only at run time'),
        ('tasks.nope.kp', [1.0], 'not a parameter'),
        ('tasks.ee.kp', [-1.0], 'outside [0, 1e+06]'),
        ('tasks.ee.kp', ['a'], 'expected a number'),
        ('tasks.ee.weight', [1.0, 2.0], 'must be one number'),
        ('tasks.ee.active', 1, 'must be true or false'),
        ('state_timeout', float('inf'), 'outside'),
        ('solver_max_iterations', 2.5, 'must be an integer'),
        ('solver_max_iterations', True, 'must be an integer'),
        ('solver_max_iterations', -1, 'outside'),
    ],
)
def test_refusals_say_why(name, value, reason):
    with pytest.raises(ParamRejected, match=reason.replace('[', r'\[').replace('+', r'\+')):
        validate(name, value, TASKS, CONSTRAINTS)


def test_live_values_are_normalised():
    assert validate('tasks.ee.kp', 50, TASKS, CONSTRAINTS)[2] == [50.0]
    assert validate('tasks.posture.weight', 2, TASKS, CONSTRAINTS)[2] == 2.0
    assert validate('solver_max_iterations', 200, TASKS, CONSTRAINTS)[2] == 200
    assert validate('constraints.torque_limit.active', False, TASKS, CONSTRAINTS)[1] == {
        'constraint': 'torque_limit'
    }


def test_reference_table_is_generated_from_the_schema():
    page = os.path.join(os.path.dirname(__file__), '..', 'docs', 'reference', 'parameters.md')
    with open(page) as fh:
        assert markdown() in fh.read(), (
            'docs parameter table out of date: python docs/_ext/parameter_reference.py'
        )
