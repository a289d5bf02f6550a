#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer) in
# build-asan/ and runs each for a bounded time on seeds made from the real recordings.
# Usage: scripts/fuzz.sh [seconds per target, default 20] [target...]
# Exit status 1 if any target found a crash, leak, timeout or out-of-memory; its input is left
# in build-asan/artifacts/<target>/ (make it a regression test). The targets' time is shared
# out over the cores (below).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET="${1:-20}"
shift || true
TARGETS=("$@")
((${#TARGETS[@]})) || TARGETS=(fuzz_hid_descriptor fuzz_hid_recorder fuzz_session_file fuzz_command_args
                               fuzz_calibration_table)

# The targets are built with the C++ tests in build-asan/ (clang, ASan + UBSan, libFuzzer's
# coverage: scripts/check.sh sanitize-build), which installs clang when missing.
BUILD=build-asan
echo "== building the fuzz targets ($BUILD/)"
scripts/check.sh sanitize-build
SEEDS="$BUILD/seeds"
rm -rf "$SEEDS"
"$BUILD/tests/fuzz/make_fuzz_seeds" "$SEEDS" tests/data/hid/*.hid

declare -A SEED_DIR=([fuzz_hid_descriptor]=hid_descriptor [fuzz_hid_recorder]=hid_recorder
                     [fuzz_session_file]=session_file [fuzz_command_args]=command_args
                     [fuzz_calibration_table]=calibration_table)
declare -A MAX_LEN=([fuzz_hid_descriptor]=4096 [fuzz_hid_recorder]=16384
                    [fuzz_session_file]=16384 [fuzz_command_args]=4096 [fuzz_calibration_table]=4096)
# fuzz <target> <seconds> <slice>: runs it that long on one core, on its corpus; its log in
# $BUILD/<target>.<slice>.log.
fuzz() {
  local target=$1 corpus="$BUILD/corpus/$1" artifacts="$BUILD/artifacts/$1"
  mkdir -p "$corpus" "$artifacts"
  # -rss_limit_mb and -timeout: unbounded memory or work is a finding, not a hang of the run.
  "$BUILD/tests/fuzz/$target" "$corpus" "$SEEDS/${SEED_DIR[$target]}" \
    -max_total_time="$2" -max_len="${MAX_LEN[$target]}" -timeout=10 -rss_limit_mb=1024 \
    -artifact_prefix="$artifacts/" -print_final_stats=1 > "$BUILD/$target.$3.log" 2>&1
}

# The targets' time laid end to end and cut into one equal share per core: a core runs its
# share's targets one after another, and a target cut at a share's end runs its time in two
# slices, on two cores, the second going on from the corpus the first left. Five targets of 20 s
# on two cores take 50 s, not the 60 s of two at a time (the fifth alone on one core).
cores=$(nproc)
total=$((${#TARGETS[@]} * SECONDS_PER_TARGET))
share=$(((total + cores - 1) / cores))
# worker <core>: its share, [core * share, (core + 1) * share) of the targets' time.
worker() {
  local from=$(($1 * share)) to=$((($1 + 1) * share)) i
  ((to > total)) && to=$total
  for i in "${!TARGETS[@]}"; do
    local start=$((i * SECONDS_PER_TARGET)) end=$(((i + 1) * SECONDS_PER_TARGET))
    ((start < from)) && start=$from
    ((end > to)) && end=$to
    ((end > start)) || continue
    fuzz "${TARGETS[i]}" $((end - start)) "$1" || echo "${TARGETS[i]}" >> "$BUILD/fuzz-failed"
  done
}

rm -f "$BUILD/fuzz-failed" "$BUILD"/fuzz_*.log
echo "== ${TARGETS[*]}: ${SECONDS_PER_TARGET} s each, on $cores cores ($share s a core)"
pids=()
for ((core = 0; core < cores; core++)); do
  worker "$core" &
  pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid" || true; done
for target in "${TARGETS[@]}"; do
  for log in "$BUILD/$target".*.log; do
    echo "$(basename "$log" .log): $(grep -E "^stat::(number_of_executed_units|peak_rss_mb)" "$log" | tr -s ' \n' '  ')"
  done
done
if [ -s "$BUILD/fuzz-failed" ]; then
  failed=$(sort -u "$BUILD/fuzz-failed" | tr '\n' ' ')
  for target in $failed; do tail -40 "$BUILD/$target".*.log; done
  echo "fuzz.sh: findings in $failed(inputs in $BUILD/artifacts/)"
  exit 1
fi
echo "fuzz.sh: no findings"
