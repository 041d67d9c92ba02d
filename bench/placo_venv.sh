#!/usr/bin/env bash
# The benchmark's side venv with PlaCo, the second peer (bench/side_venv.sh).
# PlaCo's wheel brings its own Pinocchio (pin 3.8), which must not enter the project's .venv.
# Python 3.11 (the project's): the interpreter is $PLACO_PYTHON, else python3.11 on the PATH, else pyenv's.
# Prints the venv's python path on its last line.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
exec bash "$ROOT/bench/side_venv.sh" "${PLACO_VENV:-$ROOT/.venv-placo}" \
  "$ROOT/bench/peer/placo_requirements.txt" 3.11 "${PLACO_PYTHON:-}"
