#!/usr/bin/env bash
# README command two: set up the venv if needed and run the whole test suite.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/venv.sh"
export MPLBACKEND=Agg
# the web view's browser tests drive Debian's headless chromium through its chromedriver
if [ ! -x /usr/bin/chromium ] || [ ! -x /usr/bin/chromedriver ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "installing Debian's chromium and chromium-driver (the web view's browser tests)"
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium \
        chromium-driver >/dev/null; } || echo "apt-get could not install chromium" >&2
  else
    echo "no /usr/bin/chromium or /usr/bin/chromedriver: the web view's browser tests need them" \
      "(as root: apt-get install chromium chromium-driver)" >&2
  fi
fi
# the compiled cycle's kernels into their disk cache first: no test's timing includes a cold compile
python -m orca_ros.warm
set +e
python -m pytest -q --durations=40 test "$@"
rc=$?
set -e
# pytest exits 5 when it collected no test: that is a failure of the suite, say so clearly
if [ "$rc" -eq 5 ]; then
  echo "no tests were collected" >&2
  exit 1
fi
exit "$rc"
