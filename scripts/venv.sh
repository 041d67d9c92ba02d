#!/usr/bin/env bash
# Create (once) and refresh (when requirements.txt changes) the project's virtual environment in .venv,
# then activate it. Sourced by run_demo.sh and run_tests.sh.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PY="${PYTHON:-python3}"
# PYTHON=python3.12 (or a path) selects the interpreter; each one gets its own environment
if [ -n "${PYTHON:-}" ]; then
  VENV="${ORCA_VENV:-$ROOT/.venv-py$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')}"
else
  VENV="${ORCA_VENV:-$ROOT/.venv}"
fi
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
# shellcheck disable=SC1091
source "$VENV/bin/activate"
STAMP="$VENV/.orca_requirements.sha256"
# the checkout is part of the stamp: a venv shared by two checkouts (ORCA_VENV) must import the
# package of the one running, not of the one that installed it last
WANT="$( (cat "$ROOT/requirements.txt" "$ROOT/setup.py"; echo "$ROOT") | sha256sum | cut -d' ' -f1)"
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$WANT" ]; then
  python -m pip install --quiet --upgrade pip
  python -m pip install --quiet -r "$ROOT/requirements.txt"
  python -m pip install --quiet --no-deps --no-build-isolation -e "$ROOT"
  echo "$WANT" > "$STAMP"
fi
# ament_copyright is not on PyPI: pinned .debs from Debian's archive (see the script); returns at once
# when it is installed, and only warns when Debian is out of reach (test_copyright then says so)
python "$ROOT/scripts/debian_python_tools.py" || true
cd "$ROOT"
