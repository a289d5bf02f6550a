#!/usr/bin/env bash
# The pattern gallery: sets up as the main job does (scripts/setup.sh), then renders every
# FrictionPattern on the simulated device at a slow and a fast speed (NRT, no sound card needed)
# into out/gallery/: force-against-position PNGs, a CSV per pattern and speed, and summary.md with
# the anti-aliasing figures.
# Usage: scripts/gallery.sh [--rate 48000] [--out DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/env.sh
# exec: a signal sent to this script reaches the job, which stops what it started.
exec "$KF_PYTHON" scripts/gallery/gallery_job.py "$@"
