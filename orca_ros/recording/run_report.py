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
The report of a recorded run: tracking, solve time, and which limit was touched, when, how long.

Limits come from the URDF recorded in the bag (``/robot_description``): positions, velocities and
efforts of the commanded joints. A sample counts as saturated within ``margin`` (a fraction of the
range for positions, of the limit for velocities and torques).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..robot import RobotModel


@dataclass
class JointLimits:
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    effort: np.ndarray


def joint_limits(run) -> JointLimits | None:
    """Limits of the run's joints from its URDF (None when the bag has no robot_description)."""
    if not run.urdf:
        return None
    robot = RobotModel()
    robot.load_model_from_string(run.urdf)
    names = robot.get_joint_names()
    idx = [names.index(j) for j in run.joints]
    lo, hi = robot.get_joint_position_limits()
    return JointLimits(
        lo[idx], hi[idx], robot.get_joint_velocity_limits()[idx],
        robot.get_joint_torque_limits()[idx],
    )


def saturation(run, limits: JointLimits, margin: float = 0.02):
    """
    Return ``(kind, joint, fraction of samples, first time, limit text)`` per saturated signal.

    Kinds: position, velocity, torque (the command).
    """
    found = []
    rng = limits.upper - limits.lower
    signals = []
    if run.q.size:
        finite = np.isfinite(rng) & (rng > 0)
        near = np.zeros_like(run.q, dtype=bool)
        near[:, finite] = (run.q[:, finite] - limits.lower[finite] < margin * rng[finite]) | (
            limits.upper[finite] - run.q[:, finite] < margin * rng[finite]
        )
        signals.append(('position', run.t_state, near, [
            f'[{a:.3g}, {b:.3g}]' for a, b in zip(limits.lower, limits.upper)
        ]))
        vmax = np.where(limits.velocity > 0, limits.velocity, np.inf)
        signals.append(('velocity', run.t_state, np.abs(run.v) >= (1 - margin) * vmax,
                        [f'{x:.3g}' for x in limits.velocity]))
    if run.tau.size:
        tmax = np.where(limits.effort > 0, limits.effort, np.inf)
        signals.append(('torque', run.t_command, np.abs(run.tau) >= (1 - margin) * tmax,
                        [f'{x:.3g}' for x in limits.effort]))
    for kind, t, hit, text in signals:
        for j in np.flatnonzero(hit.any(axis=0)):
            first = float(t[np.argmax(hit[:, j])])
            found.append((kind, run.joints[j], float(hit[:, j].mean()), first, text[j]))
    return found


def _fmt(x: float, unit: str) -> str:
    return f'{x + 0.0:.3g} {unit}'  # + 0.0: no '-0'


def report(run, margin: float = 0.02) -> list[str]:
    """Summary lines: configuration, coverage, tracking, solve time, saturation."""
    cfg = run.configuration()
    lines = [f'run {run.path}: {run.duration:.2f} s recorded, {run.t_state.size} joint states, '
             f'{run.t_command.size} commands, {run.t_target.size} targets']
    if cfg:
        lines.append(
            f"controller: {len(run.joints)} joints, solver {cfg.get('solver', '?')}, "
            f"{cfg.get('resolution_strategy', '?')}, {cfg.get('update_rate_hz', '?')} Hz "
            f"({cfg.get('trigger', '?')})"
        )
    if run.error.size:
        e = np.linalg.norm(run.error[:, :3], axis=1)
        lines.append(f"tracking error (position): final {_fmt(e[-1] * 1e3, 'mm')}, "
                     f"max {_fmt(e.max() * 1e3, 'mm')}")
    if run.solve_time.size:
        s = run.solve_time * 1e6
        lines.append(
            f"solve time per cycle: median {_fmt(np.median(s), 'us')}, p99 "
            f"{_fmt(np.percentile(s, 99), 'us')}, max {_fmt(s.max(), 'us')} "
            f'({s.size} cycles)'
        )
    limits = joint_limits(run)
    if limits is None:
        lines.append('limits: no robot_description in the bag')
        return lines
    sat = saturation(run, limits, margin)
    if not sat:
        lines.append(
            f'limits: no position, velocity or torque limit reached (within {margin:.0%})'
        )
    for kind, joint, frac, first, text in sat:
        lines.append(
            f'SATURATED: {joint} {kind} at its limit {text} for {frac:.1%} of the run, '
            f'first at {first:.2f} s'
        )
    return lines
