#!/usr/bin/env bash
# The speed-against-error benchmarks: scripts/setup.sh (packages, configure, build into build/,
# install the extension folder), then bench/run.py, which runs every part, prints the summary and
# the goals, and writes bench/REPORT.md, bench/results.json and the PNG plots in bench/.
# About 7 minutes on 2 cores after the build. Extra arguments go to bench/run.py, e.g.
#   scripts/bench.sh --only timing --only spatial
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --all
source scripts/env.sh
exec "$KF_PYTHON" bench/run.py "$@"
