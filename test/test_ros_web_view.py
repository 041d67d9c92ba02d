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
The web view in a real browser (issue 23): Debian's headless Chromium driven by its chromedriver.

One lockstep run of the shipped arm with ``web_view`` beside it; the page is seen through
screenshots and driven by pointer events at the places the page's camera projects the scene to.
"""

import os
import shutil
import socket
import subprocess
import sys
import time

import numpy as np
from orca_ros.ros.testing.launch_free import free_domain_id, Procs
from orca_ros.ros.testing.probe import Probe
import pytest

# Debian's names (Ubuntu's chromium-browser as a fallback)
CHROMIUM = shutil.which('chromium') or shutil.which('chromium-browser') or '/usr/bin/chromium'
CHROMEDRIVER = shutil.which('chromedriver') or '/usr/bin/chromedriver'
# the page's first view (the node's camera parameters) and the gizmo's size
CAMERA = ([0.2, -1.6, 0.9], [-0.3, 0.0, 0.4], 50.0)
GIZMO = 0.3
MAGENTA = np.array([230, 0, 230])


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def _chromium(profile):
    """Headless Chromium under chromedriver, closed network, a fresh profile."""
    if not (os.path.exists(CHROMIUM) and os.path.exists(CHROMEDRIVER)):
        msg = (f'{CHROMIUM} and {CHROMEDRIVER} needed (Debian: apt-get install chromium '
               'chromium-driver; scripts/run_tests.sh installs them when run as root)')
        if os.environ.get('CI', '').lower() in ('true', '1', 'yes'):
            pytest.fail(msg)
        pytest.skip(msg)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for flag in ('--headless', '--no-sandbox', '--disable-gpu', '--disable-quic',
                 '--no-first-run', '--disable-background-networking',
                 '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader',
                 f'--user-data-dir={profile}', '--window-size=800,560'):
        opts.add_argument(flag)
    return webdriver.Chrome(options=opts, service=Service(CHROMEDRIVER))


class Tab:
    """The page in the browser's current tab: screenshots and the camera's projection."""

    def __init__(self, driver, out):
        self.d, self.out = driver, out

    def wait(self, predicate, timeout, what):
        t0 = time.time()
        while time.time() - t0 < timeout:
            if predicate():
                return
            time.sleep(0.2)
        self.shot(self.out / 'timed_out.png')
        raise AssertionError(f'timed out after {timeout} s waiting for {what} (the tab: '
                             f"{self.out / 'timed_out.png'})")

    def canvas(self):
        """Left, top, width, height of the 3-D view (the largest canvas)."""
        return self.d.execute_script(
            'let r = null; for (const c of document.querySelectorAll("canvas")) {'
            ' const b = c.getBoundingClientRect();'
            ' if (!r || b.width * b.height > r.width * r.height) r = b; }'
            ' return r ? [r.left, r.top, r.width, r.height] : null;'
        )

    def connected(self) -> bool:
        rect = self.canvas()
        return bool(rect and rect[2] > 100) and 'Connected' in self.d.page_source

    def shot(self, path=None) -> np.ndarray:
        """Return what the tab shows (RGB array), notifications hidden (they cover the view)."""
        from io import BytesIO

        from PIL import Image

        self.d.execute_script(
            'document.querySelectorAll(".mantine-Notifications-root")'
            '.forEach(e => e.style.display = "none");'
        )
        png = self.d.get_screenshot_as_png()
        if path:
            with open(path, 'wb') as fh:
                fh.write(png)
        return np.asarray(Image.open(BytesIO(png)).convert('RGB')).astype(int)

    def project(self, p) -> np.ndarray:
        """Pixel (x, y) of world point p seen by the page's camera (vertical fov, +z up)."""
        left, top, w, h = self.canvas()
        eye, at = np.array(CAMERA[0]), np.array(CAMERA[1])
        f = (at - eye) / np.linalg.norm(at - eye)
        r = np.cross(f, [0.0, 0.0, 1.0])
        r /= np.linalg.norm(r)
        u = np.cross(r, f)
        v = np.asarray(p, dtype=float) - eye
        t = np.tan(np.radians(CAMERA[2]) / 2.0) * (v @ f)
        return np.array([left + w / 2 + (v @ r) / t * h / 2, top + h / 2 - (v @ u) / t * h / 2])

    def drag(self, start, end, steps=8):
        from selenium.webdriver.common.actions.action_builder import ActionBuilder

        ab = ActionBuilder(self.d)
        ab.pointer_action.move_to_location(int(start[0]), int(start[1])).pointer_down()
        for k in range(1, steps + 1):
            x, y = start + (end - start) * k / steps
            ab.pointer_action.move_to_location(int(round(x)), int(round(y)))
        ab.pointer_action.pointer_up()
        ab.perform()


def _magenta_centre(img):
    """Centre (x, y) of the current pose's marker (magenta pixels), None if none."""
    near = (img[..., 0] > 120) & (img[..., 2] > 120) & (img[..., 1] < 90)
    near &= np.abs(img[..., 0] - img[..., 2]) < 60
    ys, xs = np.nonzero(near)
    return None if xs.size < 10 else np.array([xs.mean(), ys.mean()])


def _gizmo_red_centre(img):
    """Centre (x, y) of the target gizmo's red parts (its x arrow and ring), None if none."""
    red = (img[..., 0] > 200) & (img[..., 1] < 110) & (img[..., 2] > 60) & (img[..., 2] < 160)
    ys, xs = np.nonzero(red)
    return None if xs.size < 10 else np.array([xs.mean(), ys.mean()])


def _patch(img, xy, half=6):
    x, y = int(xy[0]), int(xy[1])
    return img[y - half:y + half + 1, x - half:x + half + 1]


@pytest.fixture(scope='module')
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp('web_view')
    domain = free_domain_id()
    procs = Procs(domain, str(out))
    port = _free_port()
    pos, look, fov = CAMERA
    # the controller first (its start takes longest; it has its URDF from its YAML), the
    # simulator, which publishes robot_description, only after the empty scene's screenshot
    procs.start_arm_controller('lockstep')
    procs.start('orca_ros.ros.web_view', '-p', f'port:={port}', '-p', f'gizmo_scale:={GIZMO}',
                '-p', f'camera_position:={pos}', '-p', f'camera_look_at:={look}',
                '-p', f'camera_fov:={fov}', name='web_view')
    driver, probe = None, None
    try:
        procs.wait_log('web_view', 'web view: http://', 60)
        url = procs.log('web_view').split('web view: ')[1].split()[0]
        driver = _chromium(out / 'profile')
        tab = Tab(driver, out)
        driver.get(url)
        tab.wait(tab.connected, 60, 'the page connected')
        time.sleep(1.0)  # the grid drawn (nothing else comes: no robot description yet)
        empty = tab.shot(out / 'empty.png')
        procs.start_arm_bridge('lockstep')
        probe = Probe(domain)
        # the targets on the end effector's topic, whoever sends them: subscribed long before
        # the drag (a subscription matched late would miss the page's first targets)
        targets = _recorder(probe)
        probe.wait_for(lambda: probe.commands, 60, 'the controller driving the bridge')
        t0 = probe.sim_time()
        probe.wait_for(lambda: probe.sim_time() > t0 + 1.5, 60, 'the arm past its start-up')
        yield {'procs': procs, 'probe': probe, 'tab': tab, 'driver': driver, 'empty': empty,
               'out': out, 'url': url, 'targets': targets}
    finally:
        if driver is not None:
            driver.quit()
        if probe is not None:
            probe.close()
        procs.stop()
        shutil.rmtree(out / 'profile', ignore_errors=True)


def _robot_points(probe):
    """World points in the middle of three links of the arm (not the end effector)."""
    q = probe.last_state()[1]
    probe.robot.set_robot_state(q, np.zeros(7))
    return [probe.robot.get_frame_pose(f'link_{i}')[:3, 3] + probe.robot.get_frame_pose(
        f'link_{i}')[:3, :3] @ [0.0, 0.0, 0.1] for i in (1, 2, 3)]


def test_the_screenshot_shows_the_robot(run):
    tab, probe, empty = run['tab'], run['probe'], run['empty']
    points = [tab.project(p) for p in _robot_points(probe)]

    def robot_drawn():
        img = tab.shot()
        return all(np.abs(_patch(img, xy) - _patch(empty, xy)).mean() > 40 for xy in points)

    tab.wait(robot_drawn, 30, 'the robot on the page')
    img = tab.shot(run['out'] / 'robot.png')
    diffs = [np.abs(_patch(img, xy) - _patch(empty, xy)).mean() for xy in points]
    corner = np.abs(img[200:240, 20:60] - empty[200:240, 20:60]).mean()  # far from the robot
    print(f"screenshot {run['out'] / 'robot.png'}: mean difference {np.round(diffs, 1)} where "
          f'the links are, {corner:.2f} away from them')
    assert min(diffs) > 40 and corner < 2.0


def test_obstacles_sent_to_the_controller_are_shown_and_removed(run):
    from visualization_msgs.msg import Marker, MarkerArray

    tab, probe = run['tab'], run['probe']
    pub = probe.node.create_publisher(MarkerArray, '/orca_controller/obstacles', 10)
    probe.wait_for(lambda: pub.get_subscription_count() > 0, 10, 'the page on the topic')
    ball = np.array([-0.2, -0.4, 0.1])  # in front of the arm's base, clear of it and the panel
    xy = tab.project(ball)
    before = tab.shot()

    def send(action):
        m = Marker(action=action, type=Marker.SPHERE, ns='test', id=1)
        m.header.frame_id = 'world'
        m.pose.position.x, m.pose.position.y, m.pose.position.z = (float(v) for v in ball)
        m.pose.orientation.w = 1.0
        m.scale.x = m.scale.y = m.scale.z = 0.16
        pub.publish(MarkerArray(markers=[m]))

    def difference():
        return np.abs(_patch(tab.shot(), xy) - _patch(before, xy)).mean()

    tab.wait(lambda: send(Marker.ADD) or difference() > 40, 20, 'the ball on the page')
    shown = difference()
    tab.shot(run['out'] / 'obstacle.png')
    send(Marker.DELETE)  # once: the page has the topic (the ball came), a second is refused
    tab.wait(lambda: difference() < 2, 20, 'the ball gone')
    print(f'obstacle: mean difference {shown:.1f} where the ball is, {difference():.2f} after '
          'its DELETE')
    # a marker the controller would refuse: one line naming it and why, the page goes on
    arrow = Marker(action=Marker.ADD, type=Marker.ARROW, ns='test', id=2)
    pub.publish(MarkerArray(markers=[arrow]))
    run['procs'].wait_log('web_view', "obstacle marker 'test/2' not shown: type 0 is not", 10)
    assert 'Traceback' not in run['procs'].log('web_view')


def _reached(probe, target, tol=1e-3):
    return np.linalg.norm(probe.ee_pose()[:3, 3] - target[:3, 3]) < tol


def _recorder(probe):
    """Record the targets on the end effector's topic (whoever sends them)."""
    got = []
    probe.node.create_subscription(
        probe.PoseStamped, '/orca_controller/tasks/ee/target_pose', got.append, 10
    )
    return got


def _drag_ee_gizmo(run):
    """
    Drag the end effector's gizmo along its axis arrow that looks longest, towards the arm's base.

    The arm at rest near its target: the gizmo is where the last target put it (the end effector
    where no target was sent yet); after a controller restart the arm rests a few millimetres and
    tenths of a degree from it. Returns the drag's last target (4x4, base frame = world) and the
    current pose marker's centre before the drag.
    """
    tab, probe = run['tab'], run['probe']
    from orca_ros.ros.common import pose_to_matrix

    targets = run['targets']
    n = len(targets)
    at = probe.ee_pose()
    start = pose_to_matrix(targets[-1].pose) if targets else at  # the gizmo
    p0 = start[:3, 3]
    before = _magenta_centre(tab.shot())
    assert before is not None and np.linalg.norm(before - tab.project(at[:3, 3])) < 20, before
    ends = [tab.project(p0 + 0.85 * GIZMO * start[:3, i]) for i in range(3)]
    i = int(np.argmax([np.linalg.norm(e - tab.project(p0)) for e in ends]))
    axis = start[:3, i]
    on_screen = (ends[i] - tab.project(p0)) / np.linalg.norm(ends[i] - tab.project(p0))
    sign = 1.0 if axis @ -np.array([p0[0], p0[1], 0.0]) > 0 else -1.0  # inwards: reachable
    tab.drag(ends[i], ends[i] + sign * 30.0 * on_screen)
    probe.wait_for(lambda: len(targets) > n, 10, 'a target from the page')
    assert all(t.header.frame_id == 'base_link' for t in targets[n:])  # all from the page
    time.sleep(0.5)  # the drag's end: its last target
    last = targets[-1]
    goal = pose_to_matrix(last.pose)
    moved = goal[:3, 3] - p0
    along = moved @ axis
    name = 'xyz'[i]
    print(f'{len(targets) - n} targets from the drag; the last {along * 1e3:.1f} mm along the '
          f'gizmo axis {name}, {np.linalg.norm(moved - along * axis) * 1e3:.3f} mm across')
    assert last.header.frame_id == 'base_link'
    assert 0.03 < sign * along < 0.25, moved
    assert np.linalg.norm(moved - along * axis) < 1e-3
    assert np.abs(goal[:3, :3] - start[:3, :3]).max() < 1e-3  # an axis drag keeps the orientation
    return goal, before


def test_a_drag_of_the_gizmo_moves_the_arm_and_the_current_pose_follows(run):
    tab, probe = run['tab'], run['probe']
    probe.wait_for(lambda: probe.node.count_publishers('/orca_controller/tasks/ee/target_pose'),
                   10, "the page's publisher")
    p0 = probe.ee_pose()[:3, 3]
    goal, before = _drag_ee_gizmo(run)
    probe.wait_for(lambda: _reached(probe, goal), 60, 'the arm within 1 mm of the target')
    t_in = probe.sim_time()
    probe.wait_sim(0.3)
    err = np.linalg.norm(probe.ee_pose()[:3, 3] - goal[:3, 3])
    print(f'the arm within 1 mm at t = {t_in:.2f} s; {err * 1e3:.3f} mm 0.3 s later')
    assert err < 1e-3

    def followed():
        after = _magenta_centre(tab.shot())
        shift = tab.project(goal[:3, 3]) - tab.project(p0)
        return after is not None and np.linalg.norm((after - before) - shift) < 6.0

    tab.wait(followed, 20, 'the current pose marker at the new pose')
    after = _magenta_centre(tab.shot(run['out'] / 'moved.png'))
    print(f'current pose marker moved {np.round(after - before, 1)} px; the end effector '
          f'{np.round(tab.project(goal[:3, 3]) - tab.project(p0), 1)} px')
    run['goal'] = goal


def test_two_tabs_one_closed_and_a_reload_shows_the_current_state(run):
    procs, probe, tab, driver = run['procs'], run['probe'], run['tab'], run['driver']
    first = driver.current_window_handle
    driver.switch_to.new_window('tab')
    second = driver.current_window_handle
    driver.get(run['url'])
    tab.wait(tab.connected, 30, 'the second tab connected')
    # the second tab shows the state the first one left: the arm at the dragged target
    goal = run['goal']
    tab.wait(lambda: _magenta_centre(tab.shot()) is not None, 20, 'the marker in the second tab')
    there = _magenta_centre(tab.shot())
    gizmo_there = _gizmo_red_centre(tab.shot())
    off = np.linalg.norm(there - tab.project(goal[:3, 3]))
    assert off < 20.0, f'the marker {off:.1f} px from the end effector'
    # the first tab closed while the arm moves to a new target sent by someone else
    driver.switch_to.window(first)
    new = goal.copy()
    new[:3, 3] += [0.05, 0.0, 0.05]
    probe.send_target('ee', new)
    driver.close()
    driver.switch_to.window(second)
    t0 = probe.sim_time()
    probe.wait_for(lambda: _reached(probe, new), 60, 'the arm at the new target')
    took = probe.sim_time() - t0
    assert probe.sim_time() > t0 and took < 5.0  # the loop went on at its pace
    for name in ('web_view', 'controller', 'bridge'):
        assert 'Traceback' not in procs.log(name), procs.log(name)[-2000:]
    assert 'ERROR' not in procs.log('controller')
    assert all(p.poll() is None for p, _, _ in procs.procs), 'a node died'
    driver.refresh()
    tab.wait(tab.connected, 30, 'the reloaded tab connected')

    shift = tab.project(new[:3, 3]) - tab.project(goal[:3, 3])

    def shows_new_pose():
        c = _magenta_centre(tab.shot())
        return c is not None and np.linalg.norm((c - there) - shift) < 6.0

    tab.wait(shows_new_pose, 20, 'the reloaded tab showing the arm at the new target')
    img = tab.shot(run['out'] / 'reloaded.png')
    c = _magenta_centre(img)
    # the target gizmo followed the target someone else sent
    gizmo_shift = _gizmo_red_centre(img) - gizmo_there
    assert np.linalg.norm(gizmo_shift - shift) < 6.0, (gizmo_shift, shift)
    print(f'second tab: marker {off:.1f} px from the end effector; after the first tab closed '
          f'the arm reached the next target in {took:.2f} s (sim); after the reload the marker '
          f'moved {np.round(c - there, 1)} px, the target gizmo {np.round(gizmo_shift, 1)} px, '
          f'the end effector {np.round(shift, 1)} px')


def test_the_active_checkbox_toggles_the_task_and_the_error_is_shown(run):
    import re

    from selenium.webdriver.common.by import By

    probe, tab, driver = run['probe'], run['tab'], run['driver']

    def active():
        return probe.diagnostics.get('active_tasks', '').split(',')

    def box():
        return driver.find_elements(By.XPATH, "//label[normalize-space()='ee active']")

    tab.wait(lambda: box(), 20, "the task's checkbox in the panel")
    checkbox = driver.find_element(By.ID, box()[0].get_attribute('for'))
    error = driver.find_element(
        By.XPATH, "//label[normalize-space()='ee error']/following::input[1]"
    )
    tab.wait(lambda: re.fullmatch(r'\d+\.\d\d mm, \d+\.\d\d deg',
                                  error.get_attribute('value')), 10, 'the error shown')
    shown = error.get_attribute('value')
    # the box shows the diagnostics' active tasks (5 Hz), which the page may not have had yet
    # since the last test's reload
    tab.wait(lambda: checkbox.is_selected() and 'ee' in active(), 20,
             'the box checked, as the diagnostics say')
    clicked = time.time()
    box()[0].click()
    probe.wait_for(lambda: 'ee' not in active(), 20, "the controller's ee task inactive")
    # the diagnostics agree with the click by now (the probe saw it): later reports keep the box
    # unchecked, and one from before the click read late cannot check it again
    time.sleep(max(0.0, clicked + 2.6 - time.time()))
    assert not checkbox.is_selected() and 'posture' in active()
    box()[0].click()
    probe.wait_for(lambda: 'ee' in active(), 20, "the controller's ee task active again")
    assert checkbox.is_selected()
    print(f"panel: ee error shown as '{shown}'; unchecked -> active tasks without ee, checked "
          f"-> {','.join(active())}")


def _click(driver, xpath, tries=5):
    """Click the element at xpath (found again if the page re-rendered it meanwhile)."""
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.common.by import By

    for k in range(tries):
        try:
            driver.find_element(By.XPATH, xpath).click()
            return
        except StaleElementReferenceException:
            if k == tries - 1:
                raise
            time.sleep(0.2)


def test_the_solve_time_plot_shows_what_the_diagnostics_carried(run):
    import re

    from diagnostic_msgs.msg import DiagnosticArray
    from selenium.webdriver.common.by import By

    probe, tab, driver = run['probe'], run['tab'], run['driver']
    seen = set()  # (median, p99) of every report of the controller from now on

    def record(msg):
        for st in msg.status:
            if st.name.startswith('orca_controller:'):
                v = {kv.key: kv.value for kv in st.values}
                seen.add((float(v['solve_time_median_us']), float(v['solve_time_p99_us'])))

    probe.node.create_subscription(DiagnosticArray, '/diagnostics', record, 10)

    def shown():
        # read in the page (the chart re-renders at each report: no element held across it)
        titles = driver.execute_script(
            'return Array.from(document.querySelectorAll(".u-title"), e => e.textContent);'
        )
        m = [re.fullmatch(r'solve time \[us\]: median ([\d.]+), p99 ([\d.]+)', t) for t in titles]
        return [(float(x.group(1)), float(x.group(2))) for x in m if x]

    folder = "//*[normalize-space(text())='solve time']"
    tab.wait(lambda: driver.find_elements(By.XPATH, folder), 20, "the plot's folder")
    _click(driver, folder)  # folded at first
    # the page's newest values are those of a report the probe saw too (both get every one)
    tab.wait(lambda: any(p in seen for p in shown()), 20, 'the solve times of a report plotted')
    median, p99 = [p for p in shown() if p in seen][0]
    width = driver.execute_script(
        'const c = document.querySelector(".uplot canvas");'
        ' return c ? c.getBoundingClientRect().width : 0;'
    )
    tab.shot(run['out'] / 'solve_time.png')
    _click(driver, folder)
    assert width > 100 and 0.0 < median <= p99
    print(f'solve time plot: median {median} us, p99 {p99} us as in /diagnostics '
          f'({len(seen)} reports seen)')


def test_the_controller_markers_are_drawn_and_deleted(run):
    """A CoM ball and a force arrow on the controller's ~/markers appear where they are."""
    from visualization_msgs.msg import Marker, MarkerArray

    tab, probe = run['tab'], run['probe']
    pub = probe.node.create_publisher(MarkerArray, '/orca_controller/markers', 10)
    probe.wait_for(lambda: pub.get_subscription_count() > 0, 10, 'the page on the topic')
    com = np.array([-0.2, -0.4, 0.1])
    foot, top = np.array([0.05, -0.5, 0.0]), np.array([0.05, -0.5, 0.3])
    where = {'com': tab.project(com), 'arrow': tab.project(0.5 * (foot + top))}
    # the page without markers, the arm at rest: the tests before move it (the ee task toggled
    # off and on), and on a busy machine it was still on its way here. Its shadow then moved on
    # to the ball's place, and with the markers gone the page differed from a baseline taken
    # mid-motion by 2.1 (one shadow's edge), not by the markers
    before = _still(tab, probe, where)
    tab.shot(run['out'] / 'markers_before.png')

    def marker(ns, kind, action=Marker.ADD):
        m = Marker(ns=ns, id=0, type=kind, action=action)
        m.header.frame_id = 'world'
        m.pose.orientation.w = 1.0
        return m

    ball = marker('com', Marker.SPHERE)
    ball.pose.position.x, ball.pose.position.y, ball.pose.position.z = (float(v) for v in com)
    ball.scale.x = ball.scale.y = ball.scale.z = 0.12
    ball.color.r, ball.color.g, ball.color.a = 1.0, 0.85, 1.0
    arrow = marker('contact_forces', Marker.ARROW)
    arrow.points = [probe_point(foot), probe_point(top)]
    arrow.scale.x, arrow.scale.y, arrow.scale.z = 0.04, 0.06, 0.06
    arrow.color.r, arrow.color.a = 0.9, 1.0

    def differences():
        img = tab.shot()
        return {k: np.abs(_patch(img, xy, 3) - _patch(before, xy, 3)).mean()
                for k, xy in where.items()}

    # (60 s: a bound for a hung page only; a screenshot takes seconds on a busy machine)
    tab.wait(lambda: pub.publish(MarkerArray(markers=[ball, arrow]))
             or min(differences().values()) > 40, 60, 'the CoM ball and the arrow on the page')
    shown = differences()
    tab.shot(run['out'] / 'markers.png')
    # once: the page has this writer's messages (the ADD), and they come in order
    pub.publish(MarkerArray(markers=[marker('', Marker.SPHERE, Marker.DELETEALL)]))
    tab.wait(lambda: max(differences().values()) < 2, 60, 'the markers gone')
    ball_shown, arrow_shown = shown['com'], shown['arrow']
    print(f'controller markers: mean difference {ball_shown:.1f} (ball), '
          f'{arrow_shown:.1f} (arrow) where they are; '
          f'{max(differences().values()):.2f} after DELETEALL')


def _still(tab, probe, where, rest=0.2):
    """
    Return a screenshot of the arm at rest, once the page shows it so at ``where``'s patches.

    At rest: every joint slower than 1e-3 rad/s over the last ``rest`` s of simulated time (the
    arm then creeps less than 1e-4 rad more: not a pixel); shown so: two screenshots in a row
    alike there (the page draws what the bridge sent a moment ago).
    """
    def at_rest():
        with probe.lock:
            if not probe.states:
                return False
            t_end = probe.states[-1][0]
            recent = [s for s in probe.states[-2000:] if s[0] >= t_end - rest]
        return (recent[0][0] <= t_end - rest + 2e-3
                and all(np.abs(s[2]).max() < 1e-3 for s in recent))

    probe.wait_for(at_rest, 120, 'the arm at rest')
    shots = [tab.shot()]

    def alike():
        shots.append(tab.shot())
        a, b = shots[-2:]
        return all(np.array_equal(_patch(a, xy, 3), _patch(b, xy, 3)) for xy in where.values())

    tab.wait(alike, 60, 'the page showing the arm at rest')
    return shots[-1]


def probe_point(p):
    from geometry_msgs.msg import Point

    return Point(x=float(p[0]), y=float(p[1]), z=float(p[2]))


def test_an_obstacle_dragged_on_the_page_is_sent_moved(run):
    """A drag of an obstacle's gizmo sends its marker, moved along the gizmo's axis."""
    from visualization_msgs.msg import Marker, MarkerArray

    tab, probe = run['tab'], run['probe']
    topic = '/orca_controller/obstacles'
    sent = []
    probe.node.create_subscription(MarkerArray, topic, lambda m: sent.extend(m.markers), 10)
    pub = probe.node.create_publisher(MarkerArray, topic, 10)
    probe.wait_for(lambda: pub.get_subscription_count() > 0
                   and probe.node.count_publishers(topic) > 1, 10, "the page's publisher")
    p0 = np.array([-0.25, -0.45, 0.1])
    ball = Marker(action=Marker.ADD, type=Marker.SPHERE, ns='drag', id=3)
    ball.header.frame_id = 'world'
    ball.pose.position = probe_point(p0)
    ball.pose.orientation.w = 1.0
    ball.scale.x = ball.scale.y = ball.scale.z = 0.16
    before = tab.shot()
    xy = tab.project(p0)
    tab.wait(lambda: pub.publish(MarkerArray(markers=[ball]))
             or np.abs(_patch(tab.shot(), xy) - _patch(before, xy)).mean() > 40, 20,
             'the ball on the page')
    time.sleep(0.5)  # the gizmo drawn with it
    n = len(sent)
    # the gizmo's axis arrow that looks longest on the screen (scale 0.16), dragged along itself
    ends = [tab.project(p0 + 0.85 * 0.16 * np.eye(3)[i]) for i in range(3)]
    i = int(np.argmax([np.linalg.norm(e - xy) for e in ends]))
    on_screen = (ends[i] - xy) / np.linalg.norm(ends[i] - xy)
    tab.drag(ends[i], ends[i] + 30.0 * on_screen)
    probe.wait_for(lambda: len(sent) > n, 10, 'the moved obstacle from the page')
    time.sleep(0.5)  # the drag's end: its last marker
    last = sent[-1]
    p = np.array([last.pose.position.x, last.pose.position.y, last.pose.position.z])
    along = (p - p0)[i]
    across = np.linalg.norm(np.delete(p - p0, i))
    tab.shot(run['out'] / 'obstacle_dragged.png')
    pub.publish(MarkerArray(markers=[Marker(action=Marker.DELETE, ns='drag', id=3)]))
    name = 'xyz'[i]
    print(f'obstacle drag: {len(sent) - n} markers sent; the last {along * 1e3:.1f} mm along '
          f'{name}, {across * 1e3:.3f} mm across')
    assert (last.ns, last.id, last.type, last.action) == ('drag', 3, Marker.SPHERE, Marker.ADD)
    assert last.header.frame_id == 'world' and last.scale.x == 0.16
    assert 0.01 < along < 0.25 and across < 1e-3
    assert 'Traceback' not in run['procs'].log('web_view')


def test_the_page_goes_on_across_a_controller_restart_and_a_new_description(run):
    """
    The page survives a restarted controller and a changed robot description.

    The controller stopped and started again mid-run: the page's gizmo drives the new one; a new
    robot description (the arm's orange links made green) replaces the robot on the page.
    """
    procs, probe, tab = run['procs'], run['probe'], run['tab']
    old = next(p for p, _, name in procs.procs if name == 'controller')
    old.terminate()
    old.wait(timeout=30)

    def announced_again():
        with probe.lock:
            return len(probe.states) > 1 and probe.states[-1][0] == probe.states[-2][0]

    # lockstep: without a controller the simulation stands still and the bridge announces its last
    # state again (every 0.2 s): the pose the arm was left in, whatever the probe's lag (taken
    # before the stop, the probe's copy lagged the simulation by 18 mm of motion on a busy machine)
    probe.wait_for(announced_again, 60, 'the last state announced again')
    at = probe.ee_pose()
    t_stop = probe.sim_time()
    procs.start_arm_controller('lockstep', name='controller_restarted')
    probe.wait_for(lambda: probe.sim_time() > t_stop + 1.0, 90, 'the restarted controller cycling')
    held = np.linalg.norm(probe.ee_pose()[:3, 3] - at[:3, 3])
    goal, _ = _drag_ee_gizmo(run)
    probe.wait_for(lambda: _reached(probe, goal), 60, 'the arm at the target dragged after '
                   'the restart')
    for name in ('web_view', 'controller_restarted', 'bridge'):
        assert 'Traceback' not in procs.log(name), procs.log(name)[-2000:]
    print(f'controller restarted: the arm {held * 1e3:.3f} mm from where it was, then at the '
          'target dragged on the page (< 1 mm)')
    assert held < 5e-3

    import orca_ros as orca
    from orca_ros.ros.common import DESCRIPTION_QOS
    from std_msgs.msg import String

    # the shipped arm's URDF with its orange links green
    with open(orca.default_urdf_path()) as fh:
        green = fh.read().replace('rgba="1.0 0.45 0.0 1.0"', 'rgba="0.0 1.0 0.0 1.0"')
    assert 'rgba="0.0 1.0 0.0 1.0"' in green
    probe.robot.set_robot_state(probe.last_state()[1], np.zeros(7))
    link = probe.robot.get_frame_pose('link_1')  # an orange link
    xy = tab.project(link[:3, 3] + link[:3, :3] @ [0.0, 0.0, 0.1])

    def greenish():
        patch = _patch(tab.shot(), xy, 3)
        return (patch[..., 1] - np.maximum(patch[..., 0], patch[..., 2])).mean()

    before = greenish()
    pub = probe.node.create_publisher(String, '/robot_description', DESCRIPTION_QOS)
    pub.publish(String(data=green))
    tab.wait(lambda: greenish() > 60, 30, 'the green link on the page')
    tab.shot(run['out'] / 'new_description.png')
    assert procs.log('web_view').count('robot: 8 visuals') == 2  # loaded once more
    print(f'new description: green over red and blue {before:.0f} -> {greenish():.0f} where '
          'link_1 is')
    assert before < 0 and 'Traceback' not in procs.log('web_view')


def test_without_viser_one_line(tmp_path):
    """A Python without viser: ``web_view`` says so in one line; the rest imports as before."""
    (tmp_path / 'viser.py').write_text(
        "raise ModuleNotFoundError(\"No module named 'viser'\", name='viser')\n"
    )
    env = {**os.environ, 'PYTHONPATH': str(tmp_path)}
    res = subprocess.run(
        [sys.executable, '-m', 'orca_ros.ros.web_view'], env=env, capture_output=True,
        text=True, timeout=60,
    )
    lines = (res.stdout + res.stderr).strip().splitlines()
    assert res.returncode == 1
    assert lines == ["web_view needs the Python package 'viser': pip install viser==1.1.1"]
    res = subprocess.run(
        [sys.executable, '-c', 'import orca_ros.ros.web_view, orca_ros.view.page, '
         'orca_ros.view.robot_scene, orca_ros.ros.controller_node'],
        env=env, capture_output=True, text=True, timeout=60,
    )
    assert res.returncode == 0, res.stderr
