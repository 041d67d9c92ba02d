#!/usr/bin/env bash
# Create (once) and refresh (when the pins change) the benchmark's side venv with TSID, the peer controller.
# TSID's wheel needs Python 3.13: the interpreter is $TSID_PYTHON, else python3.13 on the PATH, else pyenv's.
# Prints the venv's python path on its last line.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${TSID_VENV:-$ROOT/.venv-tsid}"
REQ="$ROOT/bench/peer/tsid_requirements.txt"
PY="${TSID_PYTHON:-$(command -v python3.13 || true)}"
# pyenv's shim is on the PATH even where no 3.13 is selected: use only an interpreter that runs
if [ -n "$PY" ] && ! "$PY" -c 'import sys' >/dev/null 2>&1; then PY=""; fi
if [ -z "$PY" ]; then
  for cand in "$HOME"/.pyenv/versions/3.13*/bin/python3.13; do [ -x "$cand" ] && PY="$cand"; done
fi
if [ -z "$PY" ]; then
  echo "no Python 3.13 found for TSID's side venv: set TSID_PYTHON" >&2
  exit 2
fi
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
STAMP="$VENV/.tsid_requirements.sha256"
WANT="$(sha256sum "$REQ" | cut -d' ' -f1)"
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$WANT" ]; then
  "$VENV/bin/python" -m pip install --quiet --upgrade pip >&2
  "$VENV/bin/python" -m pip install --quiet -r "$REQ" >&2
  echo "$WANT" > "$STAMP"
fi
echo "$VENV/bin/python"
