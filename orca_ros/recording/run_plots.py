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
One figure of a recorded run, on a time axis in seconds.

Rows: tracking error (log scale, target changes marked), joint positions within their range (0 and
1 are the limits), speeds and commanded torques as fractions of their limits (1 is the limit), and
the solve time of every cycle (log scale). The title states the configuration.
"""

from __future__ import annotations

import numpy as np

from .run_report import joint_limits


def _limit_lines(ax, values=(1.0,)):
    for y in values:
        ax.axhline(y, color='red', lw=1.0, ls='--')


def plot_run(run, output: str, title: str | None = None) -> str:
    import matplotlib  # noqa: PLC0415

    if matplotlib.get_backend().lower() not in ('agg', 'pdf', 'svg'):
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    limits = joint_limits(run)
    fig, axes = plt.subplots(5, 1, figsize=(11, 13), sharex=True)
    ax = axes[0]
    if run.error.size:
        ax.semilogy(run.t_error, np.maximum(np.linalg.norm(run.error[:, :3], axis=1), 1e-7),
                    lw=1, label='position error [m]')
        ax.semilogy(run.t_error, np.maximum(np.linalg.norm(run.error[:, 3:6], axis=1), 1e-7),
                    lw=1, label='orientation error [rad]')
        ax.legend(fontsize=8, loc='upper right')
    for t in run.t_target:
        ax.axvline(t, color='grey', lw=0.6, ls=':')
    ax.set_ylabel('tracking error')
    labels = run.joints
    if limits is not None and run.q.size:
        span = limits.upper - limits.lower
        rng = np.where(np.isfinite(span), span, np.nan)
        axes[1].plot(run.t_state, (run.q - limits.lower) / rng, lw=0.8)
        _limit_lines(axes[1], (0.0, 1.0))
        axes[1].set_ylabel('position in range\n(0, 1 = limits)')
        vmax = np.where(limits.velocity > 0, limits.velocity, np.nan)
        axes[2].plot(run.t_state, np.abs(run.v) / vmax, lw=0.8)
        _limit_lines(axes[2])
        axes[2].set_ylabel('|velocity| / URDF limit')
    if limits is not None and run.tau.size:
        tmax = np.where(limits.effort > 0, limits.effort, np.nan)
        lines = axes[3].plot(run.t_command, np.abs(run.tau) / tmax, lw=0.8)
        _limit_lines(axes[3])
        axes[3].set_ylabel('|torque command| /\neffort limit')
        axes[3].legend(lines, labels, ncol=min(len(labels), 7), fontsize=7, loc='upper right')
    if run.solve_time.size:
        axes[4].semilogy(run.t_cycle, run.solve_time * 1e6, '.', ms=1.5)
        axes[4].set_ylabel('solve time [us]')
    axes[4].set_xlabel('time [s]')
    for a in axes:
        a.grid(True, which='both', alpha=0.3)
    cfg = run.configuration()
    fig.suptitle(
        title
        or f"{len(run.joints)} joints · solver {cfg.get('solver', '?')} · "
        f"{cfg.get('resolution_strategy', '?')} · {cfg.get('update_rate_hz', '?')} Hz "
        f"({cfg.get('trigger', '?')}) · {run.path}",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(output, dpi=90)
    plt.close(fig)
    return output
