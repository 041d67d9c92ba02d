#!/usr/bin/env bash
# README command two: set up the venv if needed and run the whole test suite.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/venv.sh"
export MPLBACKEND=Agg
# the compiled cycle's kernels into their disk cache first: no test's timing includes a cold compile
python -m orca_ros.optim.compiled.warm
set +e
python -m pytest -q test "$@"
rc=$?
set -e
# pytest exits 5 when it collected no test: that is a failure of the suite, say so clearly
if [ "$rc" -eq 5 ]; then
  echo "no tests were collected" >&2
  exit 1
fi
exit "$rc"
