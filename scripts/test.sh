#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), then runs every test: Catch2 (dsp, device), the
# NRT scene tests, the help files, and the realtime tests against JACK's dummy driver.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/env.sh
ctest --test-dir build --output-on-failure -j 1 "$@"
