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
import fnmatch
import importlib
import os
import pathlib
import time
from types import SimpleNamespace

import numpy as np
import orca_ros as orca
import pytest

# Optional parts: the core's tests run without ROS; the nodes' tests (and the colcon build) need
# rclpy, the colcon build colcon too. A missing (or broken: it does not import) part is reported:
# each of its files as one skipped collection with the reason, and a line at the end of the run.
# Under CI (CI=true) a skipped group fails the run: a broken install must not look like a smaller
# green suite.
OPTIONAL_GROUPS = {
    'ROS 2 nodes': ('rclpy', ('test_ros_*.py', 'test_colcon_package.py')),
    'colcon package': ('colcon_core', ('test_colcon_package.py',)),
}
_IMPORT_ERRORS: dict = {}  # module -> None (imports) or why not
_SKIPPED_GROUPS: dict = {}  # group -> (reason, [file names])


def _import_error(module: str):
    if module not in _IMPORT_ERRORS:
        try:
            importlib.import_module(module)
            _IMPORT_ERRORS[module] = None
        except Exception as exc:  # noqa: BLE001 - a broken install raises anything
            _IMPORT_ERRORS[module] = f'{type(exc).__name__}: {exc}'
    return _IMPORT_ERRORS[module]


class _SkippedModule(pytest.Module):
    """A test file of a missing optional part: never imported, reported as skipped."""

    reason = ''

    def collect(self):
        raise pytest.skip.Exception(self.reason, allow_module_level=True)


def pytest_pycollect_makemodule(module_path, parent):
    for group, (module, patterns) in OPTIONAL_GROUPS.items():
        if not any(fnmatch.fnmatch(module_path.name, p) for p in patterns):
            continue
        error = _import_error(module)
        if error is not None:
            reason = f'optional part missing: {group} (import {module}: {error})'
            _SKIPPED_GROUPS.setdefault(group, (reason, []))[1].append(module_path.name)
            skipped = _SkippedModule.from_parent(parent, path=module_path)
            skipped.reason = reason
            return skipped
    return None


@pytest.hookimpl(tryfirst=True)
def pytest_make_collect_report(collector):
    """Report a skipped module at its own file (not at the line of this file that skips it)."""
    if isinstance(collector, _SkippedModule):
        where = (str(collector.path), 1, f'Skipped: {collector.reason}')
        return pytest.CollectReport(collector.nodeid, 'skipped', where, [])
    return None


#: lines of each node's log a failed test's report shows (the last ones)
LOG_TAIL = 40


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """
    Add the end of each node's log (``*.log`` under ``tmp_path``) to a failed test's report.

    A run on CI keeps no files: what the bridge and the controller said last is the only record
    of why a system test stalled.
    """
    outcome = yield
    rep = outcome.get_result()
    tmp = getattr(item, 'funcargs', {}).get('tmp_path')
    if not rep.failed or tmp is None:
        return
    for log in sorted(pathlib.Path(tmp).rglob('*.log')):
        lines = log.read_text(errors='replace').splitlines()[-LOG_TAIL:]
        rep.sections.append((f'last {len(lines)} lines of {log.name}', '\n'.join(lines)))


def _ci() -> bool:
    return os.environ.get('CI', '').strip().lower() in ('true', '1', 'yes')


def pytest_sessionfinish(session, exitstatus):
    if _SKIPPED_GROUPS and _ci() and exitstatus in (0, pytest.ExitCode.NO_TESTS_COLLECTED):
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter):
    for group, (reason, files) in _SKIPPED_GROUPS.items():
        terminalreporter.write_line(
            f"SKIPPED {len(files)} test files ({', '.join(sorted(files))}): {reason}",
            yellow=True,
        )
    if _SKIPPED_GROUPS and _ci():
        terminalreporter.write_line(
            'FAILED: CI=true and a whole group of tests was skipped (install the missing part)',
            red=True,
            bold=True,
        )


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


@pytest.fixture(scope='session')
def quadruped_push():
    """
    Push the example's standing quadruped (PyBullet, 1 kHz) on its trunk at 0.5 s.

    ``push(gain=None, force=100.0, duration=0.1, seconds=2.0, solver='daqp', shipped=False,
    offset=None, **settings)``: ``force`` [N] a number (along y) or a 3-vector, for ``duration``
    s; ``gain`` the feet's velocity feedback gain (None: the example's); settings: the example's
    (``QuadrupedController``); ``shipped``: the controller of config/quadruped_controller.yaml
    instead, as the node builds it; ``offset``: the trunk's target moved by it at 0.5 s. Returns a
    namespace: ``room`` (the least distance of the CoM inside the feet's polygon after 0.5 s [m],
    negative outside), ``failures`` (failed cycles),
    ``failures_in_time`` (failed cycles whose update ended within the cycle's time budget: the
    budget, not a busy machine, cut them), ``longest_failed_run``, ``codes`` (return codes of the
    failed cycles), ``relaxed`` (cycles the elastic contacts carried), ``max_tilt`` (largest angle
    between the trunk's z axis and the vertical [rad]), ``slide`` (largest foot displacement after
    0.4 s [m]), ``base`` (final trunk position) and ``budget`` (the controller's solve budget:
    ``(None, None)`` is the shipped one period).
    """
    from orca_ros.examples.quadruped import (
        insert_standing,
        LEGS,
        make_robot,
        QuadrupedController,
        STAND_HEIGHT,
        state_from_sim,
    )
    from orca_ros.constraint.balance_constraint import polygon_room
    from orca_ros.sim import SimServer

    def shipped_controller():
        import yaml
        from orca_ros.configuration import build_from_config
        from orca_ros.math import make_transform

        with open(orca.share_path('config', 'quadruped_controller.yaml')) as fh:
            setup = build_from_config(yaml.safe_load(fh)['orca_controller']['ros__parameters'])
        c = setup.controller
        for name, active in setup.initially_active.items():  # as the node does
            if active:
                (c.get_task(name) if name in setup.tasks else c.get_constraint(name)).activate()
        base = setup.tasks['base'].servo_controller()
        return setup.robot, SimpleNamespace(
            controller=c, update=c.update,
            set_base_target=lambda p: base.set_desired(make_transform(p)))

    def push(gain=None, force=100.0, duration=0.1, seconds=2.0, solver='daqp', shipped=False,
             offset=None, **settings):
        if shipped:
            robot, qc = shipped_controller()
        else:
            robot = make_robot()
            qc = QuadrupedController(robot, solver, **settings)
        if gain is not None:
            for leg in LEGS:
                qc.contacts[leg].set_velocity_feedback_gain(gain)
        force = [0.0, force, 0.0] if np.ndim(force) == 0 else list(force)
        home = np.array([0.0, 0.0, STAND_HEIGHT])
        r = SimpleNamespace(failures=0, failures_in_time=0, longest_failed_run=0, codes=[],
                            relaxed=0, max_tilt=0.0, slide=0.0, base=None, room=np.inf,
                            budget=qc.controller.get_solver_budget())
        run, feet0 = 0, None
        with SimServer(time_step=0.001) as server:
            sim, by_name = insert_standing(server)
            dt = server.time_step
            for k in range(int(round(seconds / dt))):
                t = k * dt
                state_from_sim(robot, sim, by_name)
                qc.set_base_target(home + (offset if offset is not None and t >= 0.5 else 0.0))
                budget = qc.controller.get_solver_budget()[0] or dt
                t0 = time.perf_counter()
                ok = qc.update(t, dt)
                took = time.perf_counter() - t0
                if not ok:
                    r.failures += 1
                    r.failures_in_time += took <= budget
                    r.codes.append(qc.controller.get_return_code().value)
                run = 0 if ok else run + 1
                r.longest_failed_run = max(r.longest_failed_run, run)
                r.relaxed += qc.controller.contacts_relaxed()
                sim.set_joint_torque_command(qc.controller.get_joint_torque_command(), by_name)
                if 0.5 <= t < 0.5 + duration:
                    sim.apply_external_force('trunk', force)
                server.step()
                z_axis = sim.get_world_to_base_transform()[:3, 2]
                r.max_tilt = max(r.max_tilt, float(np.arccos(np.clip(z_axis[2], -1.0, 1.0))))
                feet = np.array([sim.get_link_position(f'{leg}_foot')[:2] for leg in LEGS])
                if k == 400:  # settled, before the push
                    feet0 = feet
                if feet0 is not None:
                    r.slide = max(r.slide, float(np.linalg.norm(feet - feet0, axis=1).max()))
                if t >= 0.5:
                    r.room = min(r.room, polygon_room(feet, robot.get_center_of_mass()[:2]))
            r.base = sim.get_world_to_base_transform()[:3, 3]
        return r

    return push


@pytest.fixture
def rng():
    return np.random.default_rng(1234)
