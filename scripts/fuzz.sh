#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer) in
# build-asan/ and runs each for a bounded time on seeds made from the real recordings.
# Usage: scripts/fuzz.sh [seconds per target, default 20] [target...]
# Exit status 1 if any target found a crash, leak, timeout or out-of-memory; its input is left
# in build-asan/artifacts/<target>/ (make it a regression test). The targets run as many at a
# time as there are cores, each on one.
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
# fuzz <target>: runs it for SECONDS_PER_TARGET on one core; its log in $BUILD/<target>.log.
fuzz() {
  local target=$1 corpus="$BUILD/corpus/$1" artifacts="$BUILD/artifacts/$1"
  mkdir -p "$corpus" "$artifacts"
  # -rss_limit_mb and -timeout: unbounded memory or work is a finding, not a hang of the run.
  "$BUILD/tests/fuzz/$target" "$corpus" "$SEEDS/${SEED_DIR[$target]}" \
    -max_total_time="$SECONDS_PER_TARGET" -max_len="${MAX_LEN[$target]}" -timeout=10 -rss_limit_mb=1024 \
    -artifact_prefix="$artifacts/" -print_final_stats=1 > "$BUILD/$target.log" 2>&1
}

failed=()
declare -A PID_OF=()
for ((first = 0; first < ${#TARGETS[@]}; first += $(nproc))); do
  batch=("${TARGETS[@]:first:$(nproc)}")
  echo "== ${batch[*]}: ${SECONDS_PER_TARGET} s each, side by side"
  for target in "${batch[@]}"; do
    fuzz "$target" &
    PID_OF[$target]=$!
  done
  for target in "${batch[@]}"; do
    if ! wait "${PID_OF[$target]}"; then
      failed+=("$target")
      tail -40 "$BUILD/$target.log"
    fi
    echo "$target: $(grep -E "^stat::(number_of_executed_units|peak_rss_mb)" "$BUILD/$target.log" | tr -s ' \n' '  ')"
  done
done
if ((${#failed[@]})); then
  echo "fuzz.sh: findings in ${failed[*]} (inputs in $BUILD/artifacts/)"
  exit 1
fi
echo "fuzz.sh: no findings"
