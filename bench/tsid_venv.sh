#!/usr/bin/env bash
# The benchmark's side venv with TSID, the peer controller (bench/side_venv.sh).
# TSID's wheel needs Python 3.13: the interpreter is $TSID_PYTHON, else python3.13 on the PATH, else pyenv's.
# Prints the venv's python path on its last line.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
exec bash "$ROOT/bench/side_venv.sh" "${TSID_VENV:-$ROOT/.venv-tsid}" \
  "$ROOT/bench/peer/tsid_requirements.txt" 3.13 "${TSID_PYTHON:-}"
