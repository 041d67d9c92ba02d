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
The demo.

The arm controlled by the core controller in closed loop (integrated rigid-body dynamics), from q =
0 to its target, with a report (tracking error, settle time, solve time, limit margins) and plots.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from .common import parse_args
from .simulating_results import run as run_simulation


def main(argv=None) -> int:
    def extra(p):
        p.add_argument('--output-dir', default='output', help='where the PNG plots go')
        p.add_argument('--duration', type=float, default=6.0)

    args = parse_args(__doc__, argv, extra)
    t0 = time.perf_counter()
    res = run_simulation(
        args.urdf,
        args.solver,
        duration=args.duration,
        time_budget=args.time_budget,
        base=args.base_frame,
        tool=args.tool_frame,
    )
    wall = time.perf_counter() - t0
    err = res['pos_err']
    settled = np.flatnonzero(err > 1e-3)
    settle_time = (
        res['t'][settled[-1] + 1] if settled.size and settled[-1] + 1 < len(err) else float('nan')
    )
    qlo, qhi = res['q_limits']
    q = res['q']
    pos_margin = float(np.min(np.minimum(q - qlo, qhi - q)))
    vel_margin = float(np.min(res['v_max'] - np.abs(res['v'])))
    trq_margin = float(np.min(res['tau_max'] - np.abs(res['tau'])))
    n = res['tau'].shape[1]
    print(f"=== orca_ros demo: {n}-DoF arm, Cartesian target on {res['tool']}, closed loop ===")
    print(
        f"target {np.round(res['target'][:3, 3], 4)} m, final error "
        f"{res['final_position_error'] * 1e3:.4f} mm "
        f"/ {res['final_orientation_error']:.2e} rad"
    )
    print(f'settle time (error < 1 mm for good): {settle_time:.3f} s')
    print(
        f'limit margins: position {pos_margin:.4f} rad, velocity {vel_margin:.4f} rad/s, torque '
        f'{trq_margin:.3f} Nm'
    )
    print(f"simulated {res['t'][-1] + 0.001:.1f} s in {wall:.2f} s wall time")

    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    os.makedirs(args.output_dir, exist_ok=True)
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for j in range(res['tau'].shape[1]):
        axes[0].plot(res['t'], res['tau'][:, j], label=f'joint_{j}')
    axes[0].set_ylabel('torque [Nm]')
    axes[0].legend(ncol=4, fontsize=8)
    axes[0].grid(True)
    axes[1].semilogy(res['t'], np.maximum(err, 1e-9))
    axes[1].axhline(1e-3, color='k', ls='--', lw=0.8)
    axes[1].set_ylabel('position error [m]')
    axes[1].set_xlabel('time [s]')
    axes[1].grid(True)
    fig.tight_layout()
    path = os.path.join(args.output_dir, 'demo_torques_and_error.png')
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print(f'plot: {path}')
    ok = (
        res['ok']
        and res['final_position_error'] < 1e-3
        and min(pos_margin, vel_margin, trq_margin) >= -1e-6
    )
    print('RESULT:', 'target reached within limits' if ok else 'FAILED')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
