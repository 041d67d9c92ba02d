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
The state input by kernel (robot/state_input_kernel.py) against the Python path.

Two robots, one with the kernel a compiled cycle gives it and one without, take the same states:
the same Pinocchio configuration, velocity, joint state and kinematics, bit for bit; a state the
kernel refuses is named by the Python path and leaves the previous one; inputs the kernel does
not take (lists, continuous joints) still enter.
"""

import numpy as np
import orca_ros as orca
from orca_ros.robot.state_input import _QUATERNION_TOL
import pinocchio as pin
import pytest

pytest.importorskip('numba')

from orca_ros.robot.state_input_kernel import StateKernel  # noqa: E402,I100


def _pair(urdf, floating=False):
    a, b = orca.RobotModel(), orca.RobotModel()
    for r in (a, b):
        r.load_model_from_file(urdf, floating_base=floating)
    a.buffers.state_kernel = StateKernel(a, _QUATERNION_TOL)
    return a, b


def _same(a, b):
    for name in ('v_pin', 'q', 'v'):
        np.testing.assert_array_equal(getattr(a.buffers, name), getattr(b.buffers, name),
                                      err_msg=name)
    # the base quaternion is normalised by a norm summed in another order than numpy's dot
    # (1 ulp apart); every other coordinate bit for bit
    np.testing.assert_allclose(a.buffers.q_pin, b.buffers.q_pin, rtol=0.0, atol=4e-16)
    joints = 7 if a.floating_base else 0
    np.testing.assert_array_equal(a.buffers.q_pin[joints:], b.buffers.q_pin[joints:])


def _random_configuration(model, rng):
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    return q, rng.standard_normal(model.nv)


def test_fixed_base_states_equal_the_python_path(lwr_urdf, rng):
    a, b = _pair(lwr_urdf)
    for _ in range(50):
        q, v = rng.uniform(-2, 2, 7), rng.standard_normal(7)
        for r in (a, b):
            r.set_robot_state(q, v)
        _same(a, b)
        q, v = _random_configuration(a.model, rng)
        for r in (a, b):
            r.set_configuration(q, v)
        _same(a, b)
    np.testing.assert_array_equal(a.get_frame_pose('link_7'), b.get_frame_pose('link_7'))


def test_floating_base_configurations_equal_the_python_path(example_robot_urdf, rng):
    a, b = _pair(example_robot_urdf('solo_description/robots/solo12.urdf'), floating=True)
    for _ in range(50):
        q, v = _random_configuration(a.model, rng)
        q[3:7] *= 1.0 + 5e-4  # within the tolerance: normalised on both paths
        for r in (a, b):
            r.set_configuration(q, v)
        _same(a, b)
        np.testing.assert_allclose(a.get_base_velocity(), b.get_base_velocity(), atol=1e-15)
        np.testing.assert_allclose(
            a.get_world_to_base_transform(), b.get_world_to_base_transform(), atol=1e-15
        )


def _random_base_state(model, rng):
    """Return (world_H_base, q, base twist in world axes, v) of a random floating-base state."""
    T = pin.SE3.Random().homogeneous
    nj = model.nv - 6
    return T, rng.uniform(-1.0, 1.0, nj), rng.standard_normal(6), rng.standard_normal(nj)


def test_the_five_argument_state_equals_the_python_path(example_robot_urdf, rng):
    """
    ``set_robot_state(world_H_base, q, twist, v, gravity)`` by kernel: the Python path's state.

    The quaternion as Eigen converts (1 ulp from Pinocchio's, which normalises), the base twist
    rotated into base axes summed in another order than numpy's dot (round-off); the joints,
    the pose and twist kept, bit for bit. A new gravity takes the Python path and is set.
    """
    a, b = _pair(example_robot_urdf('solo_description/robots/solo12.urdf'), floating=True)
    g = np.array([0.0, 0.0, -9.81])
    for k in range(200):
        T, q, twist, v = _random_base_state(a.model, rng)
        if k == 100:
            g = np.array([0.5, 0.0, -9.7])
        for r in (a, b):
            r.set_robot_state(T, q, twist, v, g)
        np.testing.assert_array_equal(a.buffers.q, b.buffers.q)
        np.testing.assert_array_equal(a.buffers.v, b.buffers.v)
        np.testing.assert_array_equal(a.buffers.q_pin[7:], b.buffers.q_pin[7:])
        np.testing.assert_array_equal(a.buffers.q_pin[:3], b.buffers.q_pin[:3])
        np.testing.assert_allclose(a.buffers.q_pin[3:7], b.buffers.q_pin[3:7], rtol=0.0,
                                   atol=4e-16)
        np.testing.assert_allclose(a.buffers.v_pin, b.buffers.v_pin, rtol=0.0, atol=1e-15)
        np.testing.assert_array_equal(a.get_world_to_base_transform(), T)
        np.testing.assert_array_equal(a.get_base_velocity(), b.get_base_velocity())
        np.testing.assert_array_equal(a.get_gravity(), g)
        np.testing.assert_allclose(a.get_frame_pose('FL_FOOT'), b.get_frame_pose('FL_FOOT'),
                                   rtol=0.0, atol=1e-15)
    # the kernel took them (not the Python path): a state it refuses is the test below
    assert a.buffers.state_kernel.full_state(T, q, twist, v, g)


@pytest.mark.parametrize('fault', ['nan_pose', 'not_rotation', 'reflection', 'nan_twist'])
def test_a_refused_five_argument_state_is_named_and_leaves_the_previous_one(
        example_robot_urdf, rng, fault):
    a, _ = _pair(example_robot_urdf('solo_description/robots/solo12.urdf'), floating=True)
    g = np.array([0.0, 0.0, -9.81])
    T, q, twist, v = _random_base_state(a.model, rng)
    a.set_robot_state(T, q, twist, v, g)
    before = a.buffers.q_pin.copy(), a.buffers.v_pin.copy(), a.buffers.q.copy(), a.buffers.v.copy()
    bad_T, bad_twist = T.copy(), twist.copy()
    if fault == 'nan_pose':
        bad_T[1, 2] = np.nan
        match = 'NaN or infinite'
    elif fault == 'not_rotation':
        bad_T[:3, :3] *= 1.01
        match = 'not a rotation matrix'
    elif fault == 'reflection':
        bad_T[:3, 0] *= -1.0
        match = 'not a rotation matrix'
    else:
        bad_twist[4] = np.inf
        match = 'NaN or infinite'
    assert not a.buffers.state_kernel.full_state(bad_T, q, bad_twist, v, g)
    with pytest.raises(ValueError, match=match):
        a.set_robot_state(bad_T, q, bad_twist, v, g)
    for x, y in zip(before, (a.buffers.q_pin, a.buffers.v_pin, a.buffers.q, a.buffers.v)):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize('fault', ['nan', 'inf', 'quaternion'])
def test_refused_states_are_named_and_leave_the_previous_one(example_robot_urdf, rng, fault):
    a, _ = _pair(example_robot_urdf('solo_description/robots/solo12.urdf'), floating=True)
    q, v = _random_configuration(a.model, rng)
    a.set_configuration(q, v)
    before = a.buffers.q_pin.copy(), a.buffers.v_pin.copy(), a.buffers.q.copy(), a.buffers.v.copy()
    bad_q, bad_v = q.copy(), v.copy()
    if fault == 'nan':
        bad_v[9] = np.nan
        match = 'NaN or infinite'
    elif fault == 'inf':
        bad_q[10] = np.inf
        match = 'NaN or infinite'
    else:
        bad_q[3:7] *= 1.01
        match = 'quaternion norm'
    with pytest.raises(ValueError, match=match):
        a.set_configuration(bad_q, bad_v)
    for x, y in zip(before, (a.buffers.q_pin, a.buffers.v_pin, a.buffers.q, a.buffers.v)):
        np.testing.assert_array_equal(x, y)


def test_huge_finite_values_are_not_refused(lwr_urdf):
    a, b = _pair(lwr_urdf)
    q = np.full(7, 1e308)  # their sum overflows; each is finite
    for r in (a, b):
        r.set_robot_state(q, np.zeros(7))
    _same(a, b)


def test_inputs_the_kernel_does_not_take_still_enter(lwr_urdf, example_robot_urdf, rng):
    a, b = _pair(lwr_urdf)
    q, v = list(rng.uniform(-1, 1, 7)), list(rng.standard_normal(7))
    for r in (a, b):
        r.set_robot_state(q, v)  # lists
    _same(a, b)
    q32 = np.asarray(q, dtype=np.float32)
    for r in (a, b):
        r.set_robot_state(q32, np.asarray(v)[::1])
    _same(a, b)
    # the kernel's entry point reads its arrays as 1-D, contiguous, aligned float64 without
    # checking (utils.jit.entry): every other array must take the Python path, and be read right
    wide = np.stack([rng.uniform(-1, 1, 7), np.zeros(7)], axis=1)  # a strided column
    raw = np.zeros(7 * 8 + 1, dtype=np.uint8)[1:].view(np.float64)  # misaligned
    raw[:] = rng.uniform(-1, 1, 7)
    column = np.asfortranarray(rng.uniform(-1, 1, (7, 1)))  # 2-D (the Python path ravels it)
    frozen = rng.uniform(-1, 1, 7)
    frozen.flags.writeable = False  # read-only (a message's buffer): the kernel takes it
    for qi in (wide[:, 0], raw, column, frozen, np.asarray(q, dtype=np.int64)):
        vi = rng.standard_normal(7)
        for r in (a, b):
            r.set_robot_state(qi, vi)
        _same(a, b)
        np.testing.assert_array_equal(a.buffers.q, np.asarray(qi, dtype=float).ravel())
    # continuous joints (cos/sin pairs): the Python path
    a, b = _pair(example_robot_urdf('kinova_description/robots/kinova.urdf'))
    assert not a.buffers.q_simple
    q, v = rng.uniform(-1, 1, a.ndof), rng.standard_normal(a.ndof)
    for r in (a, b):
        r.set_robot_state(q, v)
    _same(a, b)


def test_set_configuration_reads_any_float64_vector_by_its_strides(example_robot_urdf, rng):
    # set_configuration's kernel runs on float64 vectors of the right sizes whatever their
    # strides (a column, a reversed or misaligned view, a read-only buffer); every other input
    # (another dtype, 2-D, a list, big-endian) takes the Python path; each read as numpy reads it
    a, b = _pair(example_robot_urdf('panda_description/urdf/panda.urdf'))
    taken = []
    take = a.buffers.state_kernel.take
    a.buffers.state_kernel.take = lambda *args: taken.append(1) or take(*args)
    nq, nv = a.model.nq, a.model.nv
    for k, make in enumerate((
        lambda x: x.copy(),
        lambda x: np.stack([x, np.zeros_like(x)], axis=1)[:, 0],  # a strided column
        lambda x: x[::-1].copy()[::-1],  # negative strides
        lambda x: _misaligned(x),
        lambda x: _frozen(x),
        lambda x: x.astype('>f8'),  # big-endian: not float64 itself
        lambda x: x.astype(np.float32),
        lambda x: x.reshape(-1, 1),
        lambda x: list(x),
    )):
        q, v = _random_configuration(a.model, rng)
        qi, vi = make(q), make(v)
        for r in (a, b):
            r.set_configuration(qi, vi)
        _same(a, b)
        tol = 1e-7 if k == 6 else 0.0  # float32
        np.testing.assert_allclose(a.buffers.q_pin, q, rtol=tol, atol=tol)
        np.testing.assert_allclose(a.buffers.v_pin, v, rtol=tol, atol=tol)
        assert a.buffers.q_pin.shape == (nq,) and a.buffers.v_pin.shape == (nv,)
    assert len(taken) == 5  # the float64 vectors, and only they


def _misaligned(x):
    raw = np.zeros(x.size * 8 + 1, dtype=np.uint8)[1:].view(np.float64)
    raw[:] = x
    assert not raw.flags.aligned
    return raw


def _frozen(x):
    y = x.copy()
    y.flags.writeable = False
    return y


def test_a_compiled_controller_gives_its_robot_the_kernel(lwr_urdf):
    robot = orca.RobotModel()
    robot.load_model_from_file(lwr_urdf)
    robot.set_robot_state(np.zeros(7), np.zeros(7))
    assert robot.buffers.state_kernel is None
    c = orca.Controller('c', robot)
    c.update(0.0, 1e-3)
    assert isinstance(robot.buffers.state_kernel, StateKernel)
    reference = orca.RobotModel()
    reference.load_model_from_file(lwr_urdf)
    reference.set_robot_state(np.zeros(7), np.zeros(7))
    orca.Controller('r', reference, compiled=False).update(0.0, 1e-3)
    assert reference.buffers.state_kernel is None
