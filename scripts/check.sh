#!/usr/bin/env bash
# The habits CI enforces, beside the tests (scripts/test.sh runs this first):
#   format     every C++ file as clang-format (the root .clang-format) would write it
#   pyflakes   no unused import or undefined name in the Python
#   no-sc      dsp/ and device/ build and pass their tests without SuperCollider (build-nosc/)
#   sanitize   the C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/);
#              any finding fails
#   fuzz       every libFuzzer target for KF_FUZZ_SECONDS (default 20) each (scripts/fuzz.sh)
# Usage: scripts/check.sh [format|pyflakes|no-sc|sanitize|fuzz]...   (none: all, in this order)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
export CCACHE_DIR="${CCACHE_DIR:-$PWD/.ccache}"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

check_format() {
  echo "== format (clang-format $(clang-format --version | grep -o '[0-9][0-9.]*' | head -1))"
  git ls-files '*.cpp' '*.hpp' '*.h' | xargs clang-format --dry-run --Werror
}

check_pyflakes() {
  echo "== pyflakes"
  git ls-files '*.py' | xargs "$KF_PYTHON" -m pyflakes
}

# build_and_test <dir> <ctest regex> <cmake args...>
build_and_test() {
  local dir=$1 regex=$2
  shift 2
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@" > "$dir.configure.log" 2>&1 ||
    { cat "$dir.configure.log"; return 1; }
  rm -f "$dir.configure.log"
  cmake --build "$dir" -j "$(nproc)"
  ctest --test-dir "$dir" --output-on-failure -j "$(nproc)" -R "$regex"
}

check_no_sc() {
  echo "== dsp/ and device/ without SuperCollider (build-nosc/)"
  build_and_test build-nosc 'dsp/|device/' -DKF_WITH_SC=OFF
}

check_sanitize() {
  echo "== C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/)"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    build_and_test build-asan 'dsp/|device/' -DKF_WITH_SC=OFF -DKF_SANITIZE=address,undefined
}

check_fuzz() {
  echo "== fuzzing (build-fuzz/)"
  scripts/fuzz.sh "${KF_FUZZ_SECONDS:-20}"
}

checks=("$@")
((${#checks[@]})) || checks=(format pyflakes no-sc sanitize fuzz)
for check in "${checks[@]}"; do
  case "$check" in
    format) check_format ;;
    pyflakes) check_pyflakes ;;
    no-sc) check_no_sc ;;
    sanitize) check_sanitize ;;
    fuzz) check_fuzz ;;
    *) echo "unknown check: $check (format, pyflakes, no-sc, sanitize, fuzz)" >&2; exit 2 ;;
  esac
done
