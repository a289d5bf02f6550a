#!/usr/bin/env bash
# Which realtime tests need a second run against the sanitized plugin (sanitized/realtime/...,
# tests/realtime/CMakeLists.txt): the plugin built with gcov's counters (build-coverage/, -O1 as
# the sanitized one), every realtime test file run against it, two at a time, then all the scene
# tests (the sanitized run has them too), each run's counters in a folder of its own
# (build-coverage/runs/); then the tests whose plugin lines the others all run
# (scripts/coverage/sanitized_realtime.py), and whether the sanitized run's selection of help files
# still runs every line the whole help runs. Run it after a change to the plugin or the realtime
# tests, and keep tests/realtime/CMakeLists.txt's list to what it says. About 10 minutes; not part
# of the test command.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
root=$PWD out=$PWD/build-coverage/runs
cmake -S . -B build-coverage -DCMAKE_BUILD_TYPE=Release -DKF_EXTENSION_DIR="$root/build-coverage/KineticFriction" \
  -DKF_TESTS=OFF -DKF_SUPERNOVA=OFF -DCMAKE_UNITY_BUILD=OFF -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG --coverage" \
  -DCMAKE_C_FLAGS_RELEASE="-O1 -DNDEBUG --coverage" -DCMAKE_MODULE_LINKER_FLAGS=--coverage > /dev/null
cmake --build build-coverage -j "$(nproc)" --target kf_extension > /dev/null
cmake --install build-coverage > /dev/null
rm -rf "$out" && mkdir -p "$out/data"
export KF_EXTENSION_DIR=$root/build-coverage/KineticFriction KF_TEST_DATA_DIR=$root/tests/data \
  PYTHONPATH=$root/python:$root/tests PYTHONDONTWRITEBYTECODE=1 GCOV_PREFIX_STRIP=0 out KF_PYTHON

# run <folder> <name> <pytest arguments...>: one pytest run, its counters in $out/data/<name>.
run() {
  local dir=$1 name=$2 start=$SECONDS
  shift 2
  (cd "$dir" && GCOV_PREFIX=$out/data/$name "$KF_PYTHON" -m pytest -q -p no:cacheprovider -p kfharness.scratch "$@" \
    > "$out/$name.log" 2>&1) && echo "== $name" || echo "== $name FAILED: $out/$name.log"
  echo "$((SECONDS - start))" > "$out/$name.seconds"
}
export -f run
# test_jack_registry loads no plugin.
(cd tests/realtime && ls test_*.py | grep -vx test_jack_registry.py) |
  xargs -P 2 -I{} bash -c 'run tests/realtime "$(basename {} .py)" {}'
run tests/scenes scenes .
# The help files the sanitized run takes (tests/realtime/sanitized-help-files.txt), on their own: the
# report checks that they and the tests kept run every plugin line the whole help runs.
(export KF_HELP_FILES="$(grep -v '^#' tests/realtime/sanitized-help-files.txt | tr '\n' ' ')"
 run tests/realtime help_selection test_help_examples.py -k runs_on)
# Their servers are killed (a server writes its counters at exit): they keep their run.
"$KF_PYTHON" scripts/coverage/sanitized_realtime.py "$out/data" "$root" \
  test_exit_signals test_study_server_lost test_study_session test_study_resume_threshold
