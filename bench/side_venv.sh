#!/usr/bin/env bash
# Create (once) and refresh (when the pins change) one of the benchmark's side venvs (a peer's).
# Usage: side_venv.sh VENV REQUIREMENTS VERSION [PYTHON]
#   VENV: its directory; REQUIREMENTS: the pins; VERSION: the Python it needs (e.g. 3.13);
#   PYTHON: the interpreter (empty: pythonVERSION on the PATH, else pyenv's).
# Prints the venv's python path on its last line.
set -euo pipefail
VENV="$1"
REQ="$2"
VER="$3"
PY="${4:-$(command -v "python$VER" || true)}"
# pyenv's shim is on the PATH even where that version is not selected: use only one that runs
if [ -n "$PY" ] && ! "$PY" -c 'import sys' >/dev/null 2>&1; then PY=""; fi
if [ -z "$PY" ]; then
  for cand in "$HOME"/.pyenv/versions/"$VER"*/bin/python"$VER"; do [ -x "$cand" ] && PY="$cand"; done
fi
if [ -z "$PY" ]; then
  echo "no Python $VER found for the side venv $VENV: pass its interpreter" >&2
  exit 2
fi
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
STAMP="$VENV/.$(basename "$REQ" .txt).sha256"
WANT="$(sha256sum "$REQ" | cut -d' ' -f1)"
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$WANT" ]; then
  "$VENV/bin/python" -m pip install --quiet --upgrade pip >&2
  "$VENV/bin/python" -m pip install --quiet -r "$REQ" >&2
  echo "$WANT" > "$STAMP"
fi
echo "$VENV/bin/python"
