#!/usr/bin/env bash
# Create (once) and refresh (when the pins change) the benchmark's side venv with PlaCo, the second peer.
# PlaCo's wheel brings its own Pinocchio (pin 3.8), which must not enter the project's .venv.
# Python 3.11 (the project's): the interpreter is $PLACO_PYTHON, else python3.11 on the PATH, else pyenv's.
# Prints the venv's python path on its last line.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${PLACO_VENV:-$ROOT/.venv-placo}"
REQ="$ROOT/bench/peer/placo_requirements.txt"
PY="${PLACO_PYTHON:-$(command -v python3.11 || true)}"
# pyenv's shim is on the PATH even where no 3.11 is selected: use only an interpreter that runs
if [ -n "$PY" ] && ! "$PY" -c 'import sys' >/dev/null 2>&1; then PY=""; fi
if [ -z "$PY" ]; then
  for cand in "$HOME"/.pyenv/versions/3.11*/bin/python3.11; do [ -x "$cand" ] && PY="$cand"; done
fi
if [ -z "$PY" ]; then
  echo "no Python 3.11 found for PlaCo's side venv: set PLACO_PYTHON" >&2
  exit 2
fi
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
STAMP="$VENV/.placo_requirements.sha256"
WANT="$(sha256sum "$REQ" | cut -d' ' -f1)"
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$WANT" ]; then
  "$VENV/bin/python" -m pip install --quiet --upgrade pip >&2
  "$VENV/bin/python" -m pip install --quiet -r "$REQ" >&2
  echo "$WANT" > "$STAMP"
fi
echo "$VENV/bin/python"
