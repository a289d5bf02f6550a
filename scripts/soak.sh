#!/usr/bin/env bash
# Long realtime soak (not in CI): scsynth on JACK's dummy driver, 8 pilot voices on simulated
# devices with a recorder and a status poll, against a baseline of plain sines; by default with
# realtime scheduling and the load of a busy machine (2 CPU hogs, a disk writer). Reports RSS
# over time, xruns, latency percentiles, missed deadlines, watchdog trips and lost frames.
# Needs the built extension (setup.sh).
# Usage: scripts/soak.sh [--minutes 10] [--baseline-minutes 2] [--no-load] [--normal-priority]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
exec "$KF_PYTHON" tests/soak/soak.py "$@"
