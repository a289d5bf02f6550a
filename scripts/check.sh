#!/usr/bin/env bash
# The habits CI enforces, beside the tests (scripts/test.sh runs this first):
#   format     every C++ file as clang-format (the root .clang-format) would write it, and every
#              sclang line (sc-classes/) within 120 columns (also alone: sclang-lines)
#   pyflakes   no unused import or undefined name in the Python
#   sanitize   dsp/, device/ and host/ built without SuperCollider, their C++ tests under AddressSanitizer
#              + UndefinedBehaviorSanitizer (build-asan/); any finding fails
#   fuzz       every libFuzzer target for KF_FUZZ_SECONDS (default 20) each (scripts/fuzz.sh), built
#              in build-asan/ (sanitize-build alone: that build without running anything)
#   sanitize-plugin
#              the scene tests and the realtime tests with plugin lines of their own
#              (tests/realtime/CMakeLists.txt) against the plugin built with both sanitizers
#              (build-asan-plugin/, tests named sanitized/...), their runtimes preloaded into every
#              scsynth the tests start (KF_SERVER_PRELOAD); any finding fails. KF_SANITIZED_TESTS: a
#              ctest regex to run fewer of them. scripts/test.sh runs its halves,
#              sanitize-plugin-build and sanitize-plugin-findings, around one ctest with build/'s.
#   cross      the platform code off Linux, as far as this machine runs it: the Windows build
#              (MinGW-w64, no hardware backends: build-mingw/) with its dsp/, device/ and host/
#              suites under Wine, and the Clang + libc++ build with the POSIX code macOS takes
#              (build-libcxx/); both build every default target, as a user's cmake --build
#              does (the plugin .scx, the bench), and the suites; its parts cross-build,
#              cross-suites-windows and cross-suites-libcxx (scripts/test.sh runs the suites as
#              tests of its final ctest)
# Usage: scripts/check.sh [format|sclang-lines|pyflakes|sanitize|fuzz|sanitize-plugin|cross|
#                         sanitize-build|sanitize-plugin-build|sanitize-plugin-findings|cross-build|
#                         cross-suites-windows|cross-suites-libcxx]...
#        (none: all but sclang-lines, which format runs, in this order)
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

# sclang has no formatter: the one rule checked is the line length. A tab counts to the next
# multiple of 4 columns, as SuperCollider's IDE shows it. Each long line is named (file:line).
check_sclang_lines() {
  echo "== sclang lines within 120 columns (sc-classes/)"
  local file long=0
  while IFS= read -r file; do
    LC_ALL=C expand -t 4 "$file" | LC_ALL=C awk -v file="$file" '
      length > 120 { printf "%s:%d: %d columns (at most 120)\n", file, NR, length; bad = 1 }
      END { exit bad }' || long=1
  done < <(find sc-classes \( -name '*.sc' -o -name '*.sc.in' \) | sort)
  return "$long"
}

# CMake's catch_discover_tests splits a Catch2 test name at ';' into two tests that fail (each
# names no test case); commas it escapes. Each such name is printed (file: name).
check_test_names() {
  echo "== Catch2 test names without ';'"
  git ls-files 'tests/*.cpp' | xargs "$KF_PYTHON" -c '
import re, sys
bad = [f"{path}: {name}" for path in sys.argv[1:]
       for name in re.findall(r"TEST_CASE\(\s*\"((?:[^\"\\]|\\.)*)\"", open(path).read()) if ";" in name]
print("\n".join(bad)) if bad else None
sys.exit(1 if bad else 0)'
}

check_pyflakes() {
  echo "== pyflakes"
  git ls-files '*.py' | xargs "$KF_PYTHON" -m pyflakes
}

# configure_and_build <dir> <cmake args...> [-- <build args...>]. The test command's builds of
# the libraries are unity builds (-DCMAKE_UNITY_BUILD=ON; the tests' and the plugin's files stay
# one by one, tests/ and plugins/CMakeLists.txt): build-asan/ from nothing took 164 CPU-s against
# 201 file by file, build/ 342 against 433 (-j2, measured side by side). A file that lacks an
# include still fails where it is compiled alone: build-libcxx/, and a user's build/, whose
# compile install/test_readme_lines runs from a fresh copy.
configure_and_build() {
  local dir=$1
  shift
  local configure=() build=()
  while (($#)) && [[ $1 != -- ]]; do configure+=("$1"); shift; done
  (($#)) && shift && build=("$@")
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "${configure[@]}" > "$dir.configure.log" 2>&1 ||
    { cat "$dir.configure.log"; return 1; }
  rm -f "$dir.configure.log"
  cmake --build "$dir" -j "$(nproc)" "${build[@]}"
}

# build-asan/: dsp/, device/ and host/ without SuperCollider, built by clang under ASan + UBSan
# with libFuzzer's coverage, so that one build serves both the C++ tests and the fuzz targets
# (scripts/fuzz.sh builds here too). At -O1, as the sanitizers' own documentation builds: it finds
# what -O3 does (an optimiser may fold undefined behaviour away before UBSan sees it, never the
# reverse). One build instead of two (g++ for the tests, clang for the fuzz targets): 188 s and
# 368 CPU-s from nothing against about 250 s for the tests' alone, with the fuzz build's 60 s
# gone; the tests take 79 s instead of 58 (clang's -O1 and the coverage counters). build/ runs the
# same tests on the code built at -O3 by g++ (tests/CMakeLists.txt), and build-asan-plugin/
# compiles dsp/ and device/ under g++'s ASan.
build_sanitized_tests() {
  source scripts/packages.sh
  kf_install_missing clang libclang-rt-dev
  # A build-asan/ configured with g++ before this was clang's: CMake keeps a cache's compiler.
  [ -e build-asan/CMakeCache.txt ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang' build-asan/CMakeCache.txt &&
    rm -rf build-asan
  CC=clang CXX=clang++ configure_and_build build-asan -DKF_WITH_SC=OFF -DKF_SANITIZE=address,undefined -DKF_FUZZ=ON \
    -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_C_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_UNITY_BUILD=ON
}

check_sanitize() {
  echo "== dsp/, device/ and host/ without SuperCollider, C++ tests under ASan + UBSan (build-asan/)"
  build_sanitized_tests
  # One test more than the cores: many of the device suite's wait on their threads' clocks (the
  # recorded mice replayed in real time, 8 s each); at -j cores the machine was 5 to 29 % busy for
  # 20 of the 83 s they took (a fresh clone at cd9594d). Each is built to pass beside two CPU hogs.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$(($(nproc) + 1))" -R 'dsp/|device/|host/'
}

# The plugin under ASan + UBSan, its scene and realtime tests registered as sanitized/... with
# the environment their servers need (tests/CMakeLists.txt); the finding logs emptied. At -O1, as
# build-asan/ and for the same reason; the plugin's files compiled in 124 CPU-s against 190 at -O3.
build_sanitized_plugin() {
  echo "== the plugin under ASan + UBSan (build-asan-plugin/)"
  configure_and_build build-asan-plugin -DKF_SANITIZE=address,undefined -DKF_SUPERNOVA=OFF \
    -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_C_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_UNITY_BUILD=ON \
    -- --target KineticFriction
  rm -rf build-asan-plugin/sanitizer-logs && mkdir -p build-asan-plugin/sanitizer-logs
}

# A finding aborts scsynth, which fails its test; the reports also go to files, so that one in a
# server whose test did not notice (at exit, say) fails the check too. Each is shown here.
sanitized_plugin_findings() {
  echo "== sanitizer findings in the servers of the sanitized plugin's tests"
  local logs=build-asan-plugin/sanitizer-logs
  if compgen -G "$logs/*" >/dev/null; then
    echo "sanitizer findings in servers:" >&2
    cat "$logs"/* >&2
    return 1
  fi
}

check_sanitize_plugin() {
  build_sanitized_plugin
  echo "== scene and realtime tests against the plugin under ASan + UBSan"
  local rc=0
  # As scripts/test.sh runs ctest: the machine shared by resources (tests/CMakeLists.txt).
  ctest --test-dir build-asan-plugin --output-on-failure --no-tests=error -j "$(($(nproc) + 2))" \
    --resource-spec-file "$PWD/build-asan-plugin/ctest-resources.json" \
    -R "${KF_SANITIZED_TESTS:-^sanitized/(scenes|realtime)/}" || rc=$?
  sanitized_plugin_findings || rc=1
  return "$rc"
}

# The cross suites leave out what the Linux suites already run and only wall-clock time would add
# (the two 8 s real-time replays of recorded mice); under Wine, also what needs hardware
# backends ([real]) and every test that bounds a time measured by the wall clock ([wallclock]:
# a device, board or mouse thread's 1 ms grid, rates, "off within 10 ms"): Wine's sleeps on a
# loaded machine keep none of them (measured: a median release gap of 2.1 ms against 1 +- 0.2 ms
# and 315 missed deadlines beside other work; 80 frames skipped for 56 missed deadlines, a
# watchdog trip), and they are not Windows' timers, which stay untested here. Every other
# assertion of those suites counts, orders or compares values, or waits for a state with a
# bound (3 s) that only a failing test reaches. The libc++ build runs the [wallclock] tests, on
# Linux's timers, as the plain build does.
KF_CROSS_SKIP=("~hidapi backend: a real mouse's whole recording*" "~evdev backend: kernel timestamps come through exactly*")
KF_WINE_SKIP=("~[real]" "~[wallclock]")

# run_suites <build dir> <log> <runner and Catch2 arguments...>: the three suites, in order.
run_suites() {
  local dir=$1 log=$2 suite
  shift 2
  local runner=() args=()
  while (($#)) && [[ $1 != -- ]]; do runner+=("$1"); shift; done
  (($#)) && shift && args=("$@")
  for suite in tests/dsp_tests tests/device/device_tests tests/host/host_tests; do
    local exe=$dir/$suite
    [ -e "$exe.exe" ] && exe=$exe.exe
    "${runner[@]}" "$exe" "${args[@]}" > "$log.$(basename "$suite")" 2>&1 || { echo "FAILED: $exe" >> "$log"; }
  done
}

cross_build() {
  echo "== cross builds: Windows (MinGW-w64, build-mingw/), Clang + libc++ with macOS's platform code (build-libcxx/)"
  # Every default target: a user's build (the bench included) compiles what the suites do not
  # (bench/log_choice.cpp once stopped a MinGW build on M_PI, unseen while only the suites and the
  # plugin were built here).
  local start=$SECONDS
  # The libc++ build compiles file by file: the one of the test command's builds (the others are
  # unity builds, see configure_and_build) that sees an include a file lacks under macOS's library.
  # (Both at once, four compilers on the two cores, took 215 s and 423 CPU-s against 204 s and
  # 382 one after the other, measured side by side from nothing at 174859d.)
  configure_and_build build-mingw -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake -DKF_WITH_HARDWARE=OFF \
    -DKF_SUPERNOVA=OFF -DCMAKE_UNITY_BUILD=ON
  configure_and_build build-libcxx -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/clang-libcxx.cmake -DKF_PLATFORM=posix \
    -DKF_SUPERNOVA=OFF -DCMAKE_UNITY_BUILD=OFF
  echo "cross: both built in $((SECONDS - start)) s"
  # Wine's prefix (700 MB) made here, before the ctest, not by the suites' first run inside it:
  # while wineboot makes it (16 s), a SCHED_FIFO thread's 1 ms wake-ups come up to 41 ms late, 80
  # times over 10 ms in 10 s (the suites' runs with it made: at most 10 ms). Beside the study job
  # in fresh clones 100 and 101 the device threads took reports 30 to 60 ms late, force frames
  # went missing and every session's watchdog tripped for those 10 s.
  start=$SECONDS
  local wine wineserver
  wine_runner
  # What it says (a 32-bit rundll32 it does not find, among others) is shown only if it fails.
  if ! { "${wine[@]}" wineboot --init && "${wineserver[@]}" -w; } > build-mingw/wineboot.log 2>&1; then
    cat build-mingw/wineboot.log >&2
    return 1
  fi
  echo "cross: Wine's prefix made in $((SECONDS - start)) s"
}

# wine_runner: sets wine to the command that runs a Windows program as the suites do, and
# wineserver to its server's: Debian's wine64, which is not on PATH (as the toolchain file runs
# it), with the build's own prefix.
wine_runner() {
  local dir=""
  [ -x /usr/lib/wine/wine64 ] && dir=/usr/lib/wine/
  local env=(env WINEPREFIX="$PWD/build-mingw/wine-prefix" WINEDEBUG=-all WINEDLLOVERRIDES=mscoree,mshtml=)
  wine=("${env[@]}" "${dir}wine64")
  wineserver=("${env[@]}" "${dir}wineserver")
}

# cross_suites <windows|libcxx>: one cross build's three suites (under Wine for windows), each
# suite's summary, and the logs of any that failed. scripts/test.sh runs each as a test of its
# final ctest, taking a core as the other busy tests do.
cross_suites() {
  local dir runner=() skip=("${KF_CROSS_SKIP[@]}")
  case $1 in
    windows)
      dir=build-mingw
      local wine wineserver
      wine_runner
      runner=("${wine[@]}")
      skip+=("${KF_WINE_SKIP[@]}") ;;
    libcxx) dir=build-libcxx ;;
  esac
  echo "== cross suites: $1 ($dir/)"
  local start=$SECONDS log
  rm -f "$dir"/suites.log*
  run_suites "$dir" "$dir/suites.log" "${runner[@]}" -- "${skip[@]}"
  echo "cross: $1 suites ran in $((SECONDS - start)) s"
  for log in "$dir"/suites.log.*; do
    echo "$log: $(grep -E '^(All tests passed|test cases:)' "$log" | tail -1)"
  done
  if [ -e "$dir/suites.log" ]; then
    cat "$dir/suites.log" "$dir"/suites.log.* >&2
    return 1
  fi
}

check_cross() {
  echo "== cross: Windows build under Wine (build-mingw/), Clang + libc++ with macOS's platform code (build-libcxx/)"
  cross_build || return 1
  local rc=0
  cross_suites windows || rc=1
  cross_suites libcxx || rc=1
  return "$rc"
}

check_fuzz() {
  echo "== fuzzing (build-asan/)"
  scripts/fuzz.sh "${KF_FUZZ_SECONDS:-20}"
}

checks=("$@")
((${#checks[@]})) || checks=(format pyflakes sanitize fuzz sanitize-plugin cross)
for check in "${checks[@]}"; do
  case "$check" in
    format) check_format; check_sclang_lines; check_test_names ;;
    sclang-lines) check_sclang_lines ;;
    pyflakes) check_pyflakes ;;
    sanitize) check_sanitize ;;
    sanitize-build) build_sanitized_tests ;;
    fuzz) check_fuzz ;;
    sanitize-plugin) check_sanitize_plugin ;;
    sanitize-plugin-build) build_sanitized_plugin ;;
    sanitize-plugin-findings) sanitized_plugin_findings ;;
    cross) check_cross ;;
    cross-build) cross_build ;;
    cross-suites-windows) cross_suites windows ;;
    cross-suites-libcxx) cross_suites libcxx ;;
    *) echo "unknown check: $check (format, sclang-lines, pyflakes, sanitize, fuzz, sanitize-plugin, cross;" \
         "sanitize-build: sanitize's build alone; sanitize-plugin-build and sanitize-plugin-findings: its two" \
         "halves around a ctest of scripts/test.sh; cross-build, cross-suites-windows, cross-suites-libcxx: cross's parts)" >&2
       exit 2 ;;
  esac
done
