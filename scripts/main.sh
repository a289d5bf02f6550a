#!/usr/bin/env bash
# The main job: sets up (scripts/setup.sh: the packages it runs with, the plugin and classes, no
# test executables), then renders the paper's pilot interaction on the simulated device (no
# sound card needed) into out/pilot/: audio and force WAVs, CSVs, Figure 2/3-style PNGs and
# summary.md.
# Usage: scripts/main.sh [--rate 48000] [--out DIR]   (the paper ran at --rate 192000)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/env.sh
# exec: a signal sent to this script reaches the job, which stops what it started.
exec "$KF_PYTHON" scripts/pilot/main_job.py "$@"
