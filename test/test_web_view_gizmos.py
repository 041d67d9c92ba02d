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
"""The web view's ROS-free parts: the gizmos' bookkeeping and the robot's visual scene."""

import numpy as np
import orca_ros as orca
from orca_ros.view.gizmos import GizmoBook, to_matrix, to_position_wxyz
from orca_ros.view.robot_scene import RobotScene
import pytest


def _pose(xyz, angle=0.0):
    T = np.eye(4)
    c, s = np.cos(angle), np.sin(angle)
    T[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    T[:3, 3] = xyz
    return T


def test_quaternion_round_trip():
    T = _pose([0.1, -0.2, 0.3], 0.7)
    p, wxyz = to_position_wxyz(T)
    assert np.allclose(wxyz, [np.cos(0.35), 0.0, 0.0, np.sin(0.35)])
    assert np.allclose(to_matrix(p, wxyz), T)


def test_a_drag_is_sent_in_the_task_frame_at_most_every_period_and_always_at_its_end():
    book = GizmoBook(min_period=0.05)
    base = _pose([1.0, 0.0, 0.0], np.pi / 2)  # the task's frame in the world
    assert book.on_current('ee', _pose([0.2, 0.0, 0.5]), 'base_link', base)
    assert np.allclose(book.tasks['ee'].target, base @ _pose([0.2, 0.0, 0.5]))
    assert not book.on_current('ee', _pose([0.2, 0.0, 0.5]), 'base_link', base)
    world = _pose([1.0, 0.3, 0.5], np.pi / 2)
    assert book.on_drag('ee', 'start', world, 0.0, base) is None
    sent = book.on_drag('ee', 'update', world, 0.01, base)
    assert np.allclose(sent, _pose([0.3, 0.0, 0.5]))  # world -> the task's frame
    assert book.on_drag('ee', 'update', world, 0.03, base) is None  # 20 ms later: too soon
    assert book.on_drag('ee', 'update', world, 0.07, base) is not None
    # a target from elsewhere during the drag leaves the gizmo where the hand holds it
    assert not book.on_target('ee', _pose([0.0, 0.0, 0.0]))
    end = book.on_drag('ee', 'end', _pose([1.0, 0.4, 0.5], np.pi / 2), 0.071, base)
    assert np.allclose(end, _pose([0.4, 0.0, 0.5]))
    assert book.on_target('ee', _pose([0.0, 0.0, 0.0]))  # let go: others move it again
    assert not book.on_target('ee', np.full((4, 4), np.nan))


def test_no_target_before_the_task_frame_is_known():
    book = GizmoBook()
    assert book.on_drag('ee', 'end', _pose([0.0, 0.0, 0.0]), 0.0, np.eye(4)) is None


def test_the_scene_places_the_arm_as_the_controller_model_does():
    path = orca.default_urdf_path()
    with open(path) as fh:
        scene = RobotScene(fh.read(), path)
    q = [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0]
    scene.update(dict(zip(scene.joint_names, q)))
    robot = orca.RobotModel()
    robot.load_model_from_file(path)
    robot.set_robot_state(np.array(q), np.zeros(7))
    assert len(scene.visuals) == 8 and scene.root_frame == 'base_link'
    assert np.allclose(scene.frame_pose('link_7'), robot.get_frame_pose('link_7'))
    # link_7's visual: a cylinder 4 cm in radius, 3 cm long, 1.5 cm above the link's origin
    vis = scene.visuals[-1]
    T = scene.visual_poses()[-1]
    local = np.linalg.solve(robot.get_frame_pose('link_7'), T)
    assert np.allclose(local[:3, 3], [0.0, 0.0, 0.015])
    radius = np.linalg.norm(vis.vertices[:, :2], axis=1).max()
    assert np.isclose(radius, 0.04) and np.isclose(np.ptp(vis.vertices[:, 2]), 0.03)
    assert np.allclose(vis.rgba, [1.0, 0.45, 0.0, 1.0])
    # unknown joint names and NaN are left out; the state stays as it was
    scene.update({'no_joint': 1.0, 'joint_1': float('nan')})
    assert np.allclose(scene.frame_pose('link_7'), robot.get_frame_pose('link_7'))


def test_the_arm_as_mjcf_looks_as_its_urdf():
    """The scene of ``mjcf/lwr.xml`` (its file) draws the URDF's visuals where the URDF's are."""
    scenes = []
    for path in (orca.default_urdf_path(), orca.share_path('mjcf', 'lwr.xml')):
        with open(path) as fh:
            scenes.append(RobotScene(fh.read(), path))
    q = dict(zip(scenes[0].joint_names, [0.3, 0.5, -0.2, -1.2, 0.4, 0.6, -0.1]))
    for scene in scenes:
        scene.update(q)
    urdf, mjcf = scenes
    assert mjcf.joint_names == urdf.joint_names and len(mjcf.visuals) == len(urdf.visuals) == 8
    for a, b, Ta, Tb in zip(urdf.visuals, mjcf.visuals, urdf.visual_poses(), mjcf.visual_poses()):
        assert np.allclose(Ta, Tb, rtol=0.0, atol=1e-12)
        assert np.allclose(a.vertices, b.vertices, rtol=0.0, atol=1e-12)
        assert np.allclose(a.rgba, b.rgba, rtol=0.0, atol=1e-7)  # the URDF's colours are float32
    with pytest.raises(ValueError, match='MJCF text without its file'):
        RobotScene(open(orca.share_path('mjcf', 'lwr.xml')).read())


def _report(median, p99, **extra):
    """Return one controller diagnostics status' values, as the node reads them (key -> text)."""
    return {'solve_time_median_us': f'{median:.1f}', 'solve_time_p99_us': f'{p99:.1f}', **extra}


def test_the_solve_time_history_keeps_what_the_diagnostics_carried():
    from orca_ros.view.solve_times import SolveTimeHistory

    h = SolveTimeHistory(window=1.0)
    assert h.title() == 'solve time: none yet' and len(h.arrays()[0]) == 0
    reports = [(10.0 + 0.2 * k, 100.0 + k, 250.0 + 3 * k) for k in range(8)]
    for stamp, med, p99 in reports:
        assert h.add(stamp, _report(med, p99, active_tasks='ee'))
    t, med, p99 = h.arrays()
    # the last second of stamps (11.4 - 1.0 = 10.4 onwards): the last 6 reports, values as sent
    assert np.allclose(t, [-1.0, -0.8, -0.6, -0.4, -0.2, 0.0])
    assert np.array_equal(med, [r[1] for r in reports[2:]])
    assert np.array_equal(p99, [r[2] for r in reports[2:]])
    assert h.title() == 'solve time [us]: median 107.0, p99 271.0'
    # a report without solve times, or with none yet (nan), changes nothing
    assert not h.add(11.6, {'active_tasks': 'ee'})
    assert not h.add(11.6, _report(float('nan'), 1.0))
    assert not h.add(11.6, {'solve_time_median_us': 'x', 'solve_time_p99_us': '1'})
    assert len(h) == 6
    # a stamp going back (the controller restarted): a new history
    assert h.add(0.2, _report(90.0, 95.0))
    t, med, p99 = h.arrays()
    assert np.array_equal(t, [0.0]) and med[0] == 90.0 and p99[0] == 95.0


def test_the_page_plots_the_history():
    from orca_ros.view.page import Page
    from orca_ros.view.solve_times import SolveTimeHistory

    h = SolveTimeHistory()
    page = Page(port=8791)
    try:
        for k in range(3):
            h.add(float(k), _report(100.0 + k, 200.0 + k))
            page.set_solve_times(*h.arrays(), h.title())
        plot = page._solve_plot
        assert [list(a) for a in plot.data] == [[-2.0, -1.0, 0.0], [100.0, 101.0, 102.0],
                                                [200.0, 201.0, 202.0]]
        assert plot.title == 'solve time [us]: median 102.0, p99 202.0'
    finally:
        page.stop()


def test_an_arrow_mesh_from_its_start_to_its_end():
    from orca_ros.view.shapes import arrow, z_onto

    verts, faces = arrow(0.3, 0.005, 0.01, 0.03)
    assert np.isclose(verts[:, 2].min(), 0.0) and np.isclose(verts[:, 2].max(), 0.3)
    assert np.isclose(np.linalg.norm(verts[:, :2], axis=1).max(), 0.01)  # the head's radius
    assert faces.min() == 0 and faces.max() == len(verts) - 1
    short = arrow(0.01, 0.005, 0.01, 0.03)[0]  # the head at most half the arrow
    assert np.isclose(short[:, 2].max(), 0.01) and np.isclose(short[short[:, 2] > 0.0051, 2]
                                                              .min(), 0.01)
    for d in ([0.3, -0.2, 0.5], [0.0, 0.0, -2.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]):
        R = z_onto(d)
        assert np.allclose(R @ [0.0, 0.0, 1.0], np.asarray(d) / np.linalg.norm(d))
        assert np.allclose(R.T @ R, np.eye(3)) and np.isclose(np.linalg.det(R), 1.0)


def test_the_page_draws_the_controller_markers_where_they_are():
    from orca_ros.view.page import Page

    page = Page(port=8795)
    try:
        page.set_marker_sphere('com/0', [0.1, 0.2, 0.3], 0.02, (1.0, 0.85, 0.0, 1.0))
        poly = [[0.2, 0.1, 0.0], [-0.2, 0.1, 0.0], [-0.2, -0.1, 0.0], [0.2, -0.1, 0.0]]
        page.set_marker_line('support_polygon/0', poly + poly[:1], 0.006, (0.1, 0.7, 0.2, 1.0))
        page.set_marker_arrow('contact_forces/0', [0.2, 0.1, 0.0], [0.2, 0.1, 0.04], 0.01, 0.02,
                              (0.9, 0.2, 0.1, 1.0))
        com = page._markers['com/0'][1]
        assert np.allclose(com.position, [0.1, 0.2, 0.3])
        assert np.isclose(np.linalg.norm(com.vertices, axis=1).max(), 0.02)
        line = page._markers['support_polygon/0'][1]
        assert np.allclose(line.points[:, 0], poly) and np.allclose(line.points[-1, 1], poly[0])
        arrow = page._markers['contact_forces/0'][1]
        tip = to_matrix(arrow.position, arrow.wxyz) @ [0.0, 0.0, arrow.vertices[:, 2].max(), 1.0]
        assert np.allclose(tip[:3], [0.2, 0.1, 0.04])
        # a longer force: the same handle, the new length
        page.set_marker_arrow('contact_forces/0', [0.2, 0.1, 0.0], [0.25, 0.1, 0.08], 0.01,
                              0.02, (0.9, 0.2, 0.1, 1.0))
        assert page._markers['contact_forces/0'][1] is arrow
        tip = to_matrix(arrow.position, arrow.wxyz) @ [0.0, 0.0, arrow.vertices[:, 2].max(), 1.0]
        assert np.allclose(tip[:3], [0.25, 0.1, 0.08])
        page.remove_marker('com/0')
        assert sorted(page.marker_names()) == ['contact_forces/0', 'support_polygon/0']
    finally:
        page.stop()
