#!/usr/bin/env bash
# Long realtime soak (not in CI): scsynth on JACK's dummy driver, 8 pilot voices on simulated
# devices with a recorder and a status poll, against a baseline of plain sines. Reports RSS
# over time, xruns, latency percentiles and lost frames. Needs the built extension (setup.sh).
# Usage: scripts/soak.sh [--minutes 10] [--baseline-minutes 2]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
exec "$KF_PYTHON" tests/soak/soak.py "$@"
