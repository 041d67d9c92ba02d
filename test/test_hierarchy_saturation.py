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
GENERALIZED priorities swept at states where the limits bind (issue 37, item 3).

The 3-level stack (end effector level 0, an elbow pulling elsewhere level 1, posture level 2)
under the URDF's torque, position and velocity limits. At a state, a GENERALIZED controller
sweeps every priority from 0 to 1 in 1000 steps, one update per step (as
test_default_hierarchies.py sweeps at states where nothing saturates): every step at most 2 Nm,
the last (0.999 -> 1) included, and the compiled cycle equal to the Python reference path.

States: the Panda (example-robot-data) and the iiwa (pybullet_data) stretched towards a hand
target 0.9 m away, taken from their MULTI_LEVEL_WEIGHTED closed loops (bench/
bench_hierarchy_saturation.py) at cycles where a torque was at its limit, where the bands on the
locked tasks' rows as they were let the levels move by band / sigma_min along directions the
stretched arm's hand barely sees (steep in alpha, and the two paths apart: the before and after
figures are in docs/benchmarks.md); and the lwr's, its joints riding their velocity limits on
the way to a hand target 27 cm away.
"""

import numpy as np
import orca_ros as orca
from orca_ros.examples.common import add_conflicting_stack, integrate, STACK_ARMS, STACK_Q0
import pytest

pytest.importorskip('numba')

DT = 0.001
ARMS = STACK_ARMS
BEYOND_REACH = ([0.9, 0.0, 0.0], None)  # the hand's target offset (the elbow's as shipped)
# (arm, q, v): where the strict stack held a torque at its limit (see the module's docstring)
SATURATED = [
    ('panda',
     [0.2515769003130364, 1.2890660774712315, -1.3243997530058926, -0.4650819012621027,
      0.032251495483064635, 2.672150871538235, -0.38535320330702216, 0.025719283838043318,
      0.014280716161956674],
     [-0.5508698651346979, 0.10417259958512463, 0.16761071977217376, 1.0997175305458393,
      -0.5289616934501161, -0.8886700967364453, -2.2593377898348885, 0.05917101705051701,
      -0.05917101705051701]),
    ('panda',
     [0.24628284051883317, 1.2703793691220044, -1.2554662544874766, -0.4661928472723705,
      -0.017841895533635074, 2.673874381079537, -0.5954977728258506, 0.02380971387550506,
      0.01619028612449494],
     [-0.6777506435467094, -0.15453785889517502, 1.6052028108645697, 1.0824443663321102,
      0.43099769522328873, -0.6382536810202664, -2.1514361981217576, 0.08404544728938536,
      -0.08404544728938532]),
    ('iiwa',
     [0.09403498740956955, 1.4648428102469486, 1.0259854767123282, 0.009075161327148175,
      1.520919754675579, 0.00010883251872755136, 0.12132896737432779],
     [0.2814597944627751, 0.29392268321785137, 1.2893760588597047, 0.7616853292026092,
      1.9171794214281446, 1.410049886286426, 0.24180184793043877]),
    ('iiwa',
     [0.09436938425387922, 1.4601884920958688, 1.6216399938224693, 0.007087148781975768,
      0.642506784850487, -0.007684813292043539, 0.13690449609501001],
     [0.8300463926868397, 0.058899398670647, -2.7533666368072263, 1.7641905949687173,
      -2.2469666444546803, 1.6710573203892336, -0.06745039972500075]),
]


@pytest.fixture(scope='module')
def urdfs(lwr_urdf, iiwa_urdf, example_robot_urdf):
    return {'lwr': lwr_urdf, 'iiwa': iiwa_urdf,
            'panda': example_robot_urdf('panda_description/urdf/panda.urdf')}


def _make(urdf, which, strategy, offsets, compiled=True):
    ee, elbow, q0 = ARMS[which]
    q0 = np.asarray(q0, dtype=float)
    robot = orca.RobotModel()
    robot.load_model_from_file(urdf)
    robot.set_robot_state(q0, np.zeros(q0.size))
    c = orca.Controller(which, robot, strategy, compiled=compiled)
    tasks = add_conflicting_stack(c, frames=(ee, elbow), posture=q0)
    for (name, frame), off in zip((('ee', ee), ('elbow', elbow)), offsets):
        if off is not None:
            target = robot.get_frame_pose(frame)
            target[:3, 3] += off
            tasks[name].servo_controller().set_desired(target)
    c.add_constraint(orca.JointTorqueLimitConstraint, 'torque_limit')
    c.add_constraint(orca.JointPositionLimitConstraint, 'position_limit')
    c.add_constraint(orca.JointVelocityLimitConstraint, 'velocity_limit')
    c.activate_tasks_and_constraints()
    return robot, c


def _priorities(c, alpha):
    for hi in ('ee', 'elbow'):
        for lo in ('elbow', 'posture'):
            if c.get_task(hi).level < c.get_task(lo).level:
                c.set_priority(hi, lo, alpha)


def _sweep(urdf, which, offsets, q, v, compiled):
    """Return the torques of a sweep 0 -> 1 in 1000 steps at (q, v), one update per step."""
    robot, c = _make(urdf, which, 'generalized', offsets, compiled)
    _priorities(c, 0.0)
    robot.set_robot_state(np.asarray(q), np.asarray(v))
    taus = []
    for i in range(1001):
        _priorities(c, i / 1000)
        assert c.update(i * DT, DT), c.get_return_code()
        taus.append(c.get_joint_torque_command().copy())
    assert compiled == (c.compiled_cycle is not None and c.compiled_cycle.cascade is not None)
    return np.array(taus)


def _check(urdf, which, offsets, q, v):
    taus = _sweep(urdf, which, offsets, q, v, compiled=True)
    reference = _sweep(urdf, which, offsets, q, v, compiled=False)
    steps = np.abs(np.diff(taus, axis=0)).max(axis=1)
    print(f'{which}: {steps[:-1].max():.2f} Nm per step at most, {steps[-1]:.3f} on the last')
    assert steps.max() <= 2.0, f'{steps.max():.2f} Nm at alpha {(steps.argmax() + 1) / 1000}'
    # the two paths solve the same problems (test_compiled_cascade.py's agreement)
    scale = max(1.0, np.abs(reference).max())
    assert np.abs(taus - reference).max() <= 1e-9 * scale


@pytest.mark.parametrize('case', range(len(SATURATED)),
                         ids=[f'{w}{i}' for i, (w, _, _) in enumerate(SATURATED)])
def test_a_sweep_where_torques_are_at_their_limits_is_continuous(urdfs, case):
    which, q, v = SATURATED[case]
    _check(urdfs[which], which, BEYOND_REACH, q, v)


def test_a_sweep_where_velocity_limits_bind_is_continuous(urdfs):
    """The lwr on its way to a hand target 27 cm away, its joints at their velocity limits."""
    offsets = ([0.26, 0.02, 0.05], [0.2, 0.1, -0.2])
    robot, c = _make(urdfs['lwr'], 'lwr', 'multi_level_weighted', offsets)
    vmax = robot.get_joint_velocity_limits()
    q, v, at_limit = STACK_Q0.copy(), np.zeros(7), []
    for k in range(600):
        robot.set_robot_state(q, v)
        assert c.update(k * DT, DT)
        if np.any(np.abs(v) >= vmax * (1.0 - 1e-3)):
            at_limit.append((q.copy(), v.copy()))
        q, v = integrate(robot, q, v, c.get_joint_torque_command(), DT)
    assert len(at_limit) >= 20
    for q, v in (at_limit[0], at_limit[len(at_limit) // 2]):
        _check(urdfs['lwr'], 'lwr', offsets, q, v)
