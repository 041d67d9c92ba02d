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
The collision kernels' views on Pinocchio's placements and coal's results (collision_views.py).

Checked in full (every value, every address) the first time in a process; on a new
GeometryData after that (an obstacle added or removed, in the control cycle) by every address
and the first and last values. Either way each row of a view reads its own element, and
elements that are not where the view reads them are refused.
"""

import numpy as np
import orca_ros as orca
import pinocchio as pin
import pytest

pytest.importorskip('numba')


def _geometry():
    robot = orca.RobotModel()
    robot.load_model_from_file(orca.default_urdf_path())
    robot.set_robot_state(np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.8, 0.0]), np.zeros(7))
    c = orca.Controller('c', robot)
    c.add_task(orca.CartesianTask, 'ee').set_control_frame('link_7')
    col = c.add_constraint(orca.CollisionAvoidanceConstraint('collision'))
    ball = np.eye(4)
    ball[:3, 3] = [0.45, 0.0, 0.45]
    col.add_obstacle('ball', 'sphere', [0.1], ball)
    c.activate_tasks_and_constraints()
    assert c.update(0.0, 1e-3)
    return robot, col.geometry, col


def _rows_read_their_elements(robot, geom):
    from orca_ros.optim.compiled import collision_views as cv

    gm, gd = geom.geom_model, geom.geom_data
    pin.updateGeometryPlacements(robot.model, robot.data, gm, gd)
    oMg = cv.placement_view(gd, gm.ngeoms)
    res = cv.result_view(gm, gd)  # (computes every pair's distance first)
    for g in range(gm.ngeoms):
        M = gd.oMg[g]
        np.testing.assert_array_equal(oMg[g], np.r_[M.rotation.reshape(-1, order='F'),
                                                    M.translation])
    for k, r in enumerate(gd.distanceResults):
        np.testing.assert_array_equal(res[k], np.r_[r.min_distance, r.normal,
                                                    r.getNearestPoint1(), r.getNearestPoint2()])
    return len(gm.collisionPairs)


def test_views_checked_in_full_once_then_by_address(monkeypatch):
    from orca_ros.optim.compiled import collision_views as cv

    monkeypatch.setattr(cv, '_CHECKED', set())
    robot, geom, col = _geometry()
    assert cv._CHECKED == {'placements', 'results'}  # the kernels' first binding: in full
    n = _rows_read_their_elements(robot, geom)
    # a new GeometryData (one more obstacle): checked by address, and still read right
    T = np.eye(4)
    T[:3, 3] = [0.3, 0.3, 0.5]
    col.add_obstacle('box', 'box', [0.05, 0.05, 0.05], T)
    assert _rows_read_their_elements(robot, geom) > n

    class Scattered:  # placements that are not one array: refused on either path
        oMg = [pin.SE3.Random() for _ in range(3)]

    monkeypatch.setattr(cv, '_CHECKED', set())
    assert cv.placement_view(Scattered(), 3) is None  # in full
    assert not cv._CHECKED  # (a refused view teaches nothing about the layout)
    monkeypatch.setattr(cv, '_CHECKED', {'placements'})
    assert cv.placement_view(Scattered(), 3) is None  # by address
