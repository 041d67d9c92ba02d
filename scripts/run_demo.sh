#!/usr/bin/env bash
# README command one: set up the venv if needed and run the main job.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/venv.sh"
export MPLBACKEND="${MPLBACKEND:-Agg}"
python -m orca_ros.ros.main_job "$@"
