#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), runs the checks CI enforces (scripts/check.sh:
# formatting, pyflakes, the C++ tests under ASan+UBSan without SuperCollider, the fuzz targets,
# the scene and realtime tests against the sanitized plugin), then runs every
# test of build/: Catch2 (dsp, device), the NRT scene tests (with scsynth and, when installed,
# supernova), the help files, and the realtime tests against JACK's dummy driver: as many at a
# time as there are cores, except the realtime tests and the main job, which run alone (RUN_SERIAL).
# Extra arguments go to ctest, e.g. scripts/test.sh -R scenes/
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --all
source scripts/env.sh
scripts/check.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" "$@"
