#!/usr/bin/env bash
# The realtime test group three times in a row under the load of a busy machine: two CPU hogs at
# normal priority and a disk writer (python/kfharness/load.py), as the bench's loaded columns.
# A test that fails here is a defect to fix, not to retry. Needs scripts/setup.sh first.
# Usage: scripts/realtime-under-load.sh [runs (default 3)] [extra ctest arguments...]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
runs=${1:-3}
shift || true
for ((run = 1; run <= runs; run++)); do
  echo "== realtime tests under load, run $run of $runs"
  "$KF_PYTHON" -m kfharness.load -- ctest --test-dir build --output-on-failure -j 1 -R '^realtime/' "$@"
done
echo "== realtime tests under load: $runs of $runs runs passed"
