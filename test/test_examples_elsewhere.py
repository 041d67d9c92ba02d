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
The examples on arms they were not written for (issue 22).

Each example of orca_ros/examples/ was written for the shipped lwr; given another arm's URDF it
derives the base frame (the root link), the tool frame (the tip of the chain), the start posture
(inside the joint limits) and its targets (the lwr's, moved into this arm's reach sphere) from the
model (orca_ros/examples/arm.py). Here each runs on the UR5 of example-robot-data (6 joints, other
names, other lengths) or the iiwa of pybullet_data, and its own claim is checked: target reached
or tracked within the example's tolerance, limits kept, the arm held by gravity compensation, two
robots independent. quadruped.py (and its log, quadruped_log.py) run on Go1 of
example-robot-data (13 kg, 5x the shipped quadruped's mass, other names, SRDF standing pose).
"""

import numpy as np
from orca_ros.examples import (
    closed_loop_demo,
    plotting_torques,
    quadruped,
    sim_controller_in_the_loop,
    sim_gravity_compensation,
    sim_multiple_robots,
    sim_single_robot,
    simple_controller,
    simulating_results,
    using_callbacks,
    using_lambda_callbacks,
)
from orca_ros.examples.common import make_robot
from orca_ros.robot.reach import robot_reach
from orca_ros.sim import resolve_package_uris
import pytest

UR5 = 'ur_description/urdf/ur5_robot.urdf'
UR5_EFFORT = np.array([150.0, 150.0, 150.0, 28.0, 28.0, 28.0])


@pytest.fixture(scope='module')
def ur5_urdf(example_robot_urdf, tmp_path_factory):
    """Give the UR5 with its meshes' package:// names resolved (PyBullet reads it too)."""
    src = example_robot_urdf(UR5)
    path = tmp_path_factory.mktemp('ur5') / 'ur5.urdf'
    with open(src) as f:
        path.write_text(resolve_package_uris(f.read(), src))
    return str(path)


def test_simple_controller_on_the_ur5(ur5_urdf):
    res = simple_controller.run(ur5_urdf, duration=0.5)
    assert res['tool'] == 'tool0'
    assert res['solved'] == res['cycles'] == 500 and res['deactivated']
    assert np.all(np.abs(res['torque']) <= UR5_EFFORT + 1e-6)
    # the command accelerates the tool towards the target (the arm is at rest: a = J qdd)
    robot, state = make_robot(ur5_urdf)
    assert robot.get_base_frame() == 'world'
    J = robot.get_frame_jacobian('tool0')
    towards = res['target'][:3, 3] - robot.get_frame_pose('tool0')[:3, 3]
    acc = J[:3] @ res['acceleration']
    assert acc @ towards > 0.5 * np.linalg.norm(acc) * np.linalg.norm(towards)


def test_using_callbacks_on_the_ur5(ur5_urdf):
    res = using_callbacks.run(ur5_urdf, dt=0.1, ramp=0.5)
    assert res['events'] == ['activation', 'activated', 'deactivation', 'deactivated']
    assert res['deactivated'] and res['compute_calls'] == len(res['weights'])
    w = [x[1] for x in res['weights']]
    assert w[0] == 0.0 and max(w) == 1.0 and w[-1] == 0.0
    up = w.index(1.0)
    assert np.all(np.diff(w[: up + 1]) > 0) and np.all(np.diff(w[up:]) <= 0)


def test_using_lambda_callbacks_on_the_iiwa(iiwa_urdf):
    res = using_lambda_callbacks.run(iiwa_urdf, duration=2.0, loops=2)
    assert res['tool'] == 'lbr_iiwa_link_7'
    assert res['ok'] and res['loops'] == 2
    assert res['max_tracking_error'] < 1e-3  # the example's claim: tracked to within 1 mm
    assert res['first_segment_max_error'] > res['max_tracking_error']
    robot, _ = make_robot(iiwa_urdf)
    reach = robot_reach(robot, 'lbr_iiwa_link_7')
    for p in res['points']:
        assert reach.beyond(p) is None
    print(f"iiwa: tracking error max {res['max_tracking_error'] * 1e3:.3f} mm")


def test_plotting_torques_on_the_ur5(ur5_urdf, tmp_path):
    out = tmp_path / 'torques.png'
    res = plotting_torques.run(ur5_urdf, total_time=0.3, output=str(out))
    assert out.stat().st_size > 10_000
    assert res['torques'].shape == (300, 6) and np.all(np.isfinite(res['torques']))
    assert np.all(res['tau_max'] <= UR5_EFFORT)
    assert np.all(np.abs(res['torques']) <= res['tau_max'] + 1e-6)
    goal = res['target'][:3, 3]
    before = np.linalg.norm(res['start_position'] - goal)
    after = np.linalg.norm(res['final_position'] - goal)
    print(f'ur5: tool {before * 1e3:.0f} mm -> {after * 1e3:.0f} mm from the target in 0.3 s')
    assert after < 0.6 * before


def test_simulating_results_on_the_ur5(ur5_urdf):
    res = simulating_results.run(ur5_urdf, duration=10.0, time_budget=1.0)
    assert res['ok'], 'every cycle must have a solution'
    # the stated target: towards the reference's point from the shoulder (upper_arm_link), at 80 %
    # of the stretched arm's length (q = 0 is the UR5 stretched out)
    robot, _ = make_robot(ur5_urdf)
    robot.set_robot_state(np.zeros(6), np.zeros(6))
    shoulder = robot.get_frame_pose('upper_arm_link')[:3, 3]
    length = np.linalg.norm(robot.get_frame_pose('tool0')[:3, 3] - shoulder)
    assert 0.8 < length < 0.9  # 0.425 + 0.392 m of arm, the wrist's offsets
    d = simulating_results.REFERENCE_TARGET - shoulder
    np.testing.assert_allclose(
        res['target'][:3, 3], shoulder + d / np.linalg.norm(d) * 0.8 * length, atol=1e-9
    )
    print(f"ur5: final error {res['final_position_error'] * 1e3:.5f} mm, "
          f"{res['final_orientation_error']:.4f} rad")
    assert res['final_position_error'] < 1e-3 and res['final_orientation_error'] < 0.05
    qlo, qhi = res['q_limits']
    assert np.all(res['q'] >= qlo - 1e-9) and np.all(res['q'] <= qhi + 1e-9)
    assert np.all(np.abs(res['v']) <= res['v_max'] + 1e-9)
    assert np.all(res['tau_max'] <= UR5_EFFORT)
    assert np.all(np.abs(res['tau']) <= res['tau_max'] + 1e-6)
    assert np.max(np.abs(res['v'])) > 0.99 * np.min(res['v_max'])  # it had to work at the limit


def test_closed_loop_demo_on_the_ur5(ur5_urdf, tmp_path, capsys):
    code = closed_loop_demo.main(
        [ur5_urdf, '--duration', '3', '--output-dir', str(tmp_path), '--time-budget', '1.0']
    )
    out = capsys.readouterr().out
    assert '6-DoF arm, Cartesian target on tool0' in out
    assert 'RESULT: target reached within limits' in out and code == 0
    settle = float(out.split('settle time (error < 1 mm for good): ')[1].split(' s')[0])
    assert 0.0 < settle < 3.0
    assert (tmp_path / 'demo_torques_and_error.png').stat().st_size > 10_000


def _above_the_floor(urdf, q):
    """Lowest height of the UR5's links above its base's plane in posture q."""
    robot, _ = make_robot(urdf)
    robot.set_robot_state(q, np.zeros(q.size))
    return min(robot.get_frame_pose(f)[2, 3] for f in ('forearm_link', 'wrist_1_link', 'tool0'))


def test_sim_single_robot_on_the_ur5(ur5_urdf):
    res = sim_single_robot.run(ur5_urdf, duration=0.5)
    assert res['q0'].shape == (6,) and _above_the_floor(ur5_urdf, res['q0']) > 0.05
    assert np.abs(res['q'] - res['q0']).max() > 0.1  # unpowered, it falls
    assert len(res['log']) == 5  # the after-step callback ran every step (logged every 100th)


def test_sim_gravity_compensation_holds_the_ur5(ur5_urdf):
    held = sim_gravity_compensation.run(ur5_urdf, 0.5, compensate=True)
    fell = sim_gravity_compensation.run(ur5_urdf, 0.5, compensate=False)
    assert _above_the_floor(ur5_urdf, held['q0']) > 0.05  # held by the drives, not by the floor
    print(f"ur5: held {np.abs(held['q'] - held['q0']).max():.1e} rad, unpowered "
          f"{np.abs(fell['q'] - fell['q0']).max():.2f} rad")
    assert np.abs(held['q'] - held['q0']).max() < 1e-6
    assert np.abs(fell['q'] - fell['q0']).max() > 0.1
    assert np.abs(held['measured']).max() > 10.0  # the measured effort is the compensation


def test_sim_multiple_robots_on_the_iiwa(iiwa_urdf):
    res = sim_multiple_robots.run(iiwa_urdf, 0.5)
    assert res['set_ok']
    assert res['left_moved'] < 1e-6 and res['right_moved'] > 0.05
    np.testing.assert_allclose(res['bases'][0], [0, -0.6, 0], atol=1e-6)
    np.testing.assert_allclose(res['bases'][1], [0, 0.6, 0], atol=1e-6)


def test_sim_controller_in_the_loop_on_the_ur5(ur5_urdf):
    res = sim_controller_in_the_loop.run(ur5_urdf, duration=4.0)
    assert res['tool'] == 'tool0'
    robot, _ = make_robot(ur5_urdf)
    reach = robot_reach(robot, 'tool0')
    assert all(reach.beyond(p) is None for p in res['points'])
    print(f"ur5 in PyBullet: {res['legs']} legs, max error {res['max_error'] * 1e3:.2f} mm, "
          f"rms {res['rms_error'] * 1e3:.2f} mm")
    assert res['legs'] >= 1
    assert res['max_error'] < 5e-3  # the example's claim with its 2 s legs


@pytest.fixture(scope='module')
def go1_lift(example_robot_urdf, tmp_path_factory):
    """Go1 in the example: stand 1 s, lean, lift its front left foot 5 cm, set it down."""
    src = example_robot_urdf('go1_description/urdf/go1.urdf')
    path = tmp_path_factory.mktemp('go1') / 'go1.urdf'
    with open(src) as f:
        path.write_text(resolve_package_uris(f.read(), src))
    go1 = quadruped.from_urdf(str(path), example_robot_urdf('go1_description/srdf/go1.srdf'))
    log, phases, qc = quadruped.run_in_pybullet('lift', stand_time=1.0, quad=go1)
    return go1, log, phases, qc


def test_quadruped_example_on_go1(go1_lift):
    go1, log, phases, _ = go1_lift
    assert go1.trunk == 'base' and go1.foot_radius == 0.02
    assert go1.feet == {'FL': 'FL_foot', 'FR': 'FR_foot', 'HL': 'RL_foot', 'HR': 'RR_foot'}
    report = quadruped.summarize(log, phases)
    print('go1:', {k: round(v, 5) for k, v in report.items()})
    assert report['QP failures'] == 0  # the example's own check
    assert report['stand: base error max [mm]'] < 0.1  # the tutorial's claim on the shipped one
    assert report['lift: base error max [mm]'] < 1.0
    a = log.arrays()
    lift = (a['t'] >= phases['lift'][0]) & (a['t'] < phases['lift'][1])
    fl = a['feet'][lift, 0, :]
    assert fl[:, 2].max() - fl[0, 2] > 0.045  # lifted ~5 cm (PyBullet's foot)
    assert abs(fl[-1, 2] - fl[0, 2]) < 1e-4  # and set down where it stood
    assert np.linalg.norm(fl[-1, :2] - fl[0, :2]) < 2e-3


def test_quadruped_log_on_go1(go1_lift):
    _, log, phases, qc = go1_lift
    a = log.arrays()
    F, t = a['forces'], a['t']
    assert a['dynamics'].max() < 1e-8  # every solution satisfies the equation of motion
    assert a['cone'].max() < 1e-6 and F[:, :, 2].min() > -1e-6
    assert np.all(F[:, :, 2] <= a['bounds'] + 1e-6)
    lift = (t >= phases['lift'][0]) & (t < phases['lift'][1])
    assert a['bounds'][lift, 0].min() == 0.0 and not a['loaded'][lift, 0].all()
    assert a['loaded'][~lift].all()  # the other phases stand on four feet
    # 13 kg on the feet, summed over the four: the weight once settled
    settled = (t > 0.5) & ~lift
    weight = 9.81 * qc.robot.get_total_mass()
    np.testing.assert_allclose(F[settled, :, 2].sum(axis=1), weight, rtol=0.05)
    dt = t[1] - t[0]
    for i in range(4):  # the loaded feet do not slide (< 0.1 mm, the shipped robot's bound)
        on = a['loaded'][:, i] & (t >= 0.5)
        edges = np.flatnonzero(np.diff(np.concatenate(([0], on.astype(int), [0]))))
        for start, stop in zip(edges[::2], edges[1::2]):
            path = np.cumsum(a['slip'][start:stop, i], axis=0) * dt
            assert np.linalg.norm(path, axis=1).max() < 1e-4


def test_on_the_lwr_the_derivation_changes_nothing(lwr_urdf, example_robot_urdf):
    from orca_ros.examples.arm import posture, shoulder_frame, to_reach, tool_frame

    robot, state = make_robot(lwr_urdf)
    assert (robot.get_base_frame(), tool_frame(robot), shoulder_frame(robot)) == (
        'base_link', 'link_7', 'link_2')
    assert np.all(state.joint_pos == 0.0)
    for q in ([0.0, 0.3, 0.0, -0.3, 0.0, 0.2, 0.0], [0.4, 0.8, -0.3, -1.1, 0.5, 0.7, 0.1],
              [0.2, 0.6, 0.0, -1.0, 0.0, 0.5, 0.0], [-0.2, 0.4, 0.3, -0.8, 0.0, 0.4, 0.0],
              [0.0, 0.6, 0.0, -1.4, 0.0, 0.9, 0.0]):  # the examples' postures
        assert np.array_equal(posture(robot, q), q)
    for p in ([1.0, 0.75, 0.5], [0.3, -0.5, 0.41], [0.5, 0.2, 0.5], [0.45, 0.25, 0.55]):
        assert np.array_equal(to_reach(robot, 'link_7', p), p)
    panda, _ = make_robot(example_robot_urdf('panda_description/urdf/panda.urdf'))
    assert tool_frame(panda) == 'panda_hand_tcp'  # where the fingers branch off
