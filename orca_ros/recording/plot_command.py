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
``plot BAG``: draw a recorded run and print its report (what saturated, when).

``ros2 run orca_ros plot <bag>`` under ROS, ``plot <bag>`` in the venv. Writes ``<bag>.png`` next
to the bag unless ``--output`` says otherwise.
"""

from __future__ import annotations

import argparse
import os
import sys

from .recorded_run import read_run
from .run_plots import plot_run
from .run_report import report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('bag', help='rosbag2 directory (or .mcap file) written by bag_recorder')
    ap.add_argument('--output', help='PNG to write [<bag>.png]')
    ap.add_argument('--title', help='figure title [the configuration]')
    ap.add_argument('--margin', type=float, default=0.02,
                    help='a sample this close to a limit (fraction) counts as saturated')
    args = ap.parse_args(argv)
    if not os.path.exists(args.bag):
        print(f"plot: no bag at '{args.bag}'", file=sys.stderr)
        return 2
    run = read_run(args.bag)
    for line in report(run, args.margin):
        print(line)
    out = args.output or os.path.normpath(args.bag).rstrip(os.sep) + '.png'
    print(f'plot: {plot_run(run, out, args.title)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
