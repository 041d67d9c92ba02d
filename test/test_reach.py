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
"""The reach sphere of a frame from the kinematic chain (orca_ros.robot.reach)."""

import numpy as np
import orca_ros as orca
from orca_ros.robot.reach import robot_reach
import pinocchio as pin
import pytest


def _load(path, floating=False):
    robot = orca.RobotModel()
    robot.load_model_from_file(path, floating)
    return robot


def _farthest(robot, reach, rng, samples=2000):
    """Return the largest distance from the centre over random configurations within limits."""
    m = robot.model
    d = m.createData()
    lo = np.maximum(m.lowerPositionLimit, -10.0)  # a free flyer's translation: any finite box
    hi = np.minimum(m.upperPositionLimit, 10.0)
    root, frame = m.getFrameId(reach.root), m.getFrameId(reach.frame)
    far = 0.0
    for _ in range(samples):
        pin.framesForwardKinematics(m, d, pin.randomConfiguration(m, lo, hi))
        p = d.oMf[root].actInv(d.oMf[frame]).translation
        far = max(far, reach.distance(p))
    return far


@pytest.mark.parametrize('which', ['lwr', 'iiwa'])
def test_a_straight_arm_reaches_exactly_its_sphere(which, lwr_urdf, iiwa_urdf, rng):
    """Arms whose links line up at q = 0: stretched there, the frame is on the sphere."""
    robot = _load(lwr_urdf if which == 'lwr' else iiwa_urdf)
    frame = robot.model.frames[-1].name  # the last link
    reach = robot_reach(robot, frame)
    robot.set_configuration(pin.neutral(robot.model), np.zeros(robot.model.nv))
    stretched = reach.distance(robot.get_frame_pose(frame)[:3, 3])
    assert abs(stretched - reach.radius) < 1e-12, (stretched, reach.radius)
    assert _farthest(robot, reach, rng) <= reach.radius + 1e-12
    # out of reach: just beyond the stretched frame, not just within it
    out = reach.center + (reach.radius + 1e-3) * np.array([1.0, 0.0, 0.0])
    assert reach.beyond(out) == pytest.approx(reach.radius + 1e-3)
    assert reach.beyond(reach.center + (reach.radius - 1e-3) * np.array([0.0, 1.0, 0.0])) is None
    text = reach.refusal('ee', out)
    assert "task 'ee'" in text and 'out of reach' in text
    assert f'{reach.radius + 1e-3:.3f} m' in text and f'{reach.radius:.3f} m' in text


def test_offsets_and_prismatic_fingers_stay_inside(example_robot_urdf, rng):
    """Panda (offset links, prismatic fingers) and UR5 (shoulder offsets): a bound, not vacuous."""
    panda = _load(example_robot_urdf('panda_description/urdf/panda.urdf'))
    ur5 = _load(example_robot_urdf('ur_description/urdf/ur5_robot.urdf'))
    for robot, frame in ((panda, 'panda_leftfinger'), (panda, 'panda_hand'), (ur5, 'tool0')):
        reach = robot_reach(robot, frame)
        far = _farthest(robot, reach, rng)
        # measured 0.85 (Panda's finger), 0.87 (its hand), 0.76 (UR5) of the radius
        assert 0.7 * reach.radius < far <= reach.radius + 1e-12, (frame, far, reach.radius)
    # fingers locked (another driver's joints) still move: the finger's reach is the same
    finger = robot_reach(panda, 'panda_leftfinger').radius
    panda.lock_joints(['panda_finger_joint1', 'panda_finger_joint2'])
    assert robot_reach(panda, 'panda_leftfinger').radius == finger


def test_a_tree_and_a_floating_base(example_robot_urdf, rng):
    """Talos: one hand from the other (two branches); from the world, unbounded (free flyer)."""
    talos = _load(example_robot_urdf('talos_data/robots/talos_reduced.urdf'), floating=True)
    hands = robot_reach(talos, 'arm_left_7_link', 'arm_right_7_link')
    assert np.isfinite(hands.radius)
    assert 0.9 * hands.radius < _farthest(talos, hands, rng, 1000) <= hands.radius + 1e-12
    foot = robot_reach(talos, 'leg_left_6_link')  # from the base frame, the trunk
    assert foot.root == 'base_link'
    assert _farthest(talos, foot, rng, 1000) <= foot.radius + 1e-12
    free = robot_reach(talos, 'arm_left_7_link', 'world')
    assert free.radius == np.inf and free.beyond(np.array([1e6, 0.0, 0.0])) is None
