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
Speed of the working tree against a commit: the same benchmarks, the two trees interleaved.

A refactor must keep the speed of the control cycle (issue 40, acceptance 4: within 5 % of the
commit before the change). The commit REF is checked out in a worktree of its own,
/tmp/orca-tree-<short sha> (made with ``git worktree add --detach`` if it is not there yet,
reused otherwise; a fresh one first fills its kernels' disk cache with
``python -m orca_ros.warm``, minutes on a busy machine). Every measurement is one
process run in the tree's root with the tree's root first on PYTHONPATH, which checks that it
imported that tree's ``orca_ros`` (not the editable install of the venv) and stops otherwise. The
jobs, each process giving one median per cycle or step (microseconds):

* tsid: ``bench/peer/run_orca.py SCENARIO`` (its ``median_us``: set_robot_state + update() +
  the torque command) for the panda, quadruped and talos scenarios, one process each;
* levels: ``bench/bench_levels.py``'s ``run`` with DAQP for the one-level weighted row, the
  three-level strict row and the three-level GENERALIZED row (priorities 0.5): 200 cycles of
  warm-up, then ``--cycles`` timed, one process each;
* collision: ``bench/bench_collision.py --one with`` and ``--one without`` (its ``median``).

Before the rounds, one process per job and tree that is not counted (numba loads, or compiles,
each tree's kernels). In each round every measurement runs in REF then in the working tree, the
order swapped from one round to the next (a busy spell of the machine hits both alike). Printed:
each measurement's median over the rounds in each tree, their ratio (tree / REF), and whether
every ratio is within the target (1.05); the exit code is 0 either way.

Usage: python bench/bench_trees.py REF [--rounds 5] [--jobs tsid,levels,collision] [--steps N]
       [--cycles 3000]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import runpy
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
TARGET = 1.05
JOBS = ('tsid', 'levels', 'collision')
SCENARIOS = ('panda', 'quadruped', 'talos')
LEVEL_ROWS = {
    'one_level_weighted': (3, None),
    'multi_level_weighted': (3, None),
    'generalized': (3, 0.5),
}
COLLISION = ('with', 'without')
WARMUP_STEPS = 200  # tsid steps and levels cycles of the uncounted warm-up processes


def measurements(jobs) -> list[tuple[str, str]]:
    """Return the (job, case) pairs of the jobs, one process each per tree and round."""
    cases = {'tsid': SCENARIOS, 'levels': tuple(LEVEL_ROWS), 'collision': COLLISION}
    return [(job, case) for job in jobs for case in cases[job]]


# ---- the child: one measurement in the tree it runs in (cwd) ------------------------------------


def _check_from_tree(root: str, module) -> None:
    where = os.path.realpath(module.__file__)
    if not where.startswith(root + os.sep):
        raise SystemExit(
            f'bench_trees: {module.__name__} imported from {where}, not from the tree {root}'
        )


def _run_script(path: str, args: list[str]) -> dict:
    """Run ``path`` as a script (its folder first on sys.path); return its last JSON line."""
    sys.path[0] = os.path.dirname(path)
    sys.argv = [path] + args
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        runpy.run_path(path, run_name='__main__')
    lines = out.getvalue().strip().splitlines()
    if not lines:
        raise SystemExit(f'bench_trees: {path} {args} printed nothing')
    return json.loads(lines[-1])


def _tsid(root: str, scenario: str, steps: int | None) -> float:
    args = [scenario] + ([] if steps is None else ['--steps', str(steps)])
    got = _run_script(os.path.join(root, 'bench', 'peer', 'run_orca.py'), args)
    return float(got['median_us'])


def _levels(root: str, strategy: str, cycles: int) -> float:
    sys.path[0] = 'bench'  # the tree's bench (cwd: its root), not this script's folder
    import bench_levels  # noqa: PLC0415

    _check_from_tree(root, bench_levels)
    n_tasks, priority = LEVEL_ROWS[strategy]
    bench_levels.run(strategy, 'daqp', n_tasks, 200, priority)  # warm-up
    return float(bench_levels.run(strategy, 'daqp', n_tasks, cycles, priority)[0])


def _collision(root: str, which: str) -> float:
    got = _run_script(os.path.join(root, 'bench', 'bench_collision.py'), ['--one', which])
    return float(got['median'])


def child(job: str, case: str, steps: int | None, cycles: int) -> int:
    """
    Run one measurement (or, with case ``warmup``, all of the job's, short) in the cwd's tree.

    Prints one JSON line: the median per cycle (``median_us``) and where orca_ros came from.
    """
    root = os.path.realpath(os.getcwd())
    import orca_ros  # noqa: PLC0415

    _check_from_tree(root, orca_ros)
    if job == 'warm':
        sys.path[0] = root  # as ``python -m`` in the tree's root
        sys.argv = ['warm']
        # (orca_ros.warm since issue 40; orca_ros.optim.compiled.warm in the trees before)
        new = os.path.exists(os.path.join(root, 'orca_ros', 'warm.py'))
        runpy.run_module('orca_ros.warm' if new else 'orca_ros.optim.compiled.warm',
                         run_name='__main__')
        return 0
    cases = [c for j, c in measurements([job])] if case == 'warmup' else [case]
    if case == 'warmup':
        steps, cycles = WARMUP_STEPS, WARMUP_STEPS
    for c in cases:
        if job == 'tsid':
            us = _tsid(root, c, steps)
        elif job == 'levels':
            us = _levels(root, c, cycles)
        else:
            us = _collision(root, c)
    print(json.dumps({'median_us': us, 'orca_ros': os.path.realpath(orca_ros.__file__)}))
    return 0


# ---- the parent: trees, rounds, table -----------------------------------------------------------


def _git(*args: str) -> str:
    return subprocess.run(['git', '-C', ROOT, *args], check=True, capture_output=True,
                          text=True).stdout.strip()


def ref_tree(ref: str) -> tuple[str, str, str, bool]:
    """Return (sha, short sha, worktree of REF, whether it was just made), making it if needed."""
    sha = _git('rev-parse', '--verify', f'{ref}^{{commit}}')
    short = _git('rev-parse', '--short', sha)
    path = f'/tmp/orca-tree-{short}'
    if os.path.exists(path):
        head = subprocess.run(['git', '-C', path, 'rev-parse', 'HEAD'], check=True,
                              capture_output=True, text=True).stdout.strip()
        if head != sha:
            raise SystemExit(f'bench_trees: {path} is at {head}, not at {sha} ({ref})')
        return sha, short, path, False
    subprocess.run(['git', '-C', ROOT, 'worktree', 'add', '--detach', path, sha], check=True)
    return sha, short, path, True


def run_child(tree: str, job: str, case: str, args) -> float | None:
    """Run one child process in ``tree`` (its root first on PYTHONPATH); its median in us."""
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(p for p in (tree, env.get('PYTHONPATH')) if p)
    cmd = [sys.executable, os.path.realpath(__file__), '--child', job, case,
           '--cycles', str(args.cycles)]
    if args.steps is not None:
        cmd += ['--steps', str(args.steps)]
    done = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        sys.stderr.write(done.stdout + done.stderr)
        raise SystemExit(f'bench_trees: {job} {case} failed in {tree} (exit {done.returncode})')
    if job == 'warm':
        sys.stdout.write(done.stdout)
        return None
    got = json.loads(done.stdout.strip().splitlines()[-1])
    if not got['orca_ros'].startswith(os.path.realpath(tree) + os.sep):
        where = got['orca_ros']
        raise SystemExit(f'bench_trees: orca_ros came from {where}, not from {tree}')
    return float(got['median_us'])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument('ref', nargs='?', help='the commit to compare the working tree with')
    ap.add_argument('--rounds', type=int, default=5)
    ap.add_argument('--jobs', default=','.join(JOBS), help='of ' + ','.join(JOBS))
    ap.add_argument('--steps', type=int, default=None, help='run_orca.py steps (tsid)')
    ap.add_argument('--cycles', type=int, default=3000, help='timed cycles (levels)')
    ap.add_argument('--child', nargs=2, metavar=('JOB', 'CASE'), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        return child(*args.child, args.steps, args.cycles)
    if not args.ref:
        ap.error('REF is required')
    jobs = args.jobs.split(',')
    unknown = [j for j in jobs if j not in JOBS]
    if unknown:
        ap.error('unknown jobs: ' + ','.join(unknown) + ' (of ' + ','.join(JOBS) + ')')
    sha, short, ref_path, fresh = ref_tree(args.ref)
    trees = [(short, ref_path), ('tree', ROOT)]
    if fresh and os.path.exists(os.path.join(ref_path, 'orca_ros', 'optim', 'compiled',
                                             'warm.py')):
        print(f'{ref_path}: a fresh worktree, compiling its kernels (minutes)...', flush=True)
        t0 = time.perf_counter()
        run_child(ref_path, 'warm', '-', args)
        print(f'  done in {time.perf_counter() - t0:.0f} s', flush=True)
    print('warm-up (not counted): ' + ', '.join(jobs) + f' in {short} and in the working tree',
          flush=True)
    for job in jobs:
        for _, path in trees:
            run_child(path, job, 'warmup', args)
    cases = measurements(jobs)
    got = {(tree, case): [] for tree, _ in trees for case in cases}
    for r in range(args.rounds):
        order = trees if r % 2 == 0 else trees[::-1]
        for case in cases:
            for label, path in order:
                got[(label, case)].append(run_child(path, *case, args))
            print(f'round {r + 1}: {case[0]} {case[1]}: '
                  + ', '.join(f'{label} {got[(label, case)][-1]:.1f} us' for label, _ in order),
                  flush=True)
    print(f'\nmedian per cycle over {args.rounds} interleaved rounds (us); {short}: REF {sha}, '
          f'tree: the working tree {ROOT}')
    print('job'.ljust(32) + short.rjust(10) + 'tree'.rjust(10) + 'ratio'.rjust(8))
    over = []
    for case in cases:
        ref_us = statistics.median(got[(short, case)])
        tree_us = statistics.median(got[('tree', case)])
        ratio = tree_us / ref_us
        if ratio > TARGET:
            over.append(f'{case[0]} {case[1]} ({ratio:.3f})')
        name = f'{case[0]} {case[1]}'
        print(f'{name:<32}{ref_us:>10.1f}{tree_us:>10.1f}{ratio:>8.3f}')
    if over:
        print(f'NOT within {TARGET:.2f}x of {short}: ' + ', '.join(over))
    else:
        print(f'every ratio within {TARGET:.2f}x of {short} (target met)')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
