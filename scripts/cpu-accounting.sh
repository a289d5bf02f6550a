#!/usr/bin/env bash
# Where a command's CPU time goes: the kernel's process accounting (Debian's acct; root) records
# every process as it ends, with its parent and CPU time. The report (scripts/accounting/report.py)
# sums them by process name and, for each ctest in the command's output, by test (a test's process
# tree). It found the texture model, run in Python by three tests, at a tenth of the test command's
# Python time, and Qt WebEngine's helper processes at 49 CPU-s. Not part of the test command.
# It turns off any system-wide accounting that was on (accton has one file at a time).
# Usage: scripts/cpu-accounting.sh COMMAND... (e.g. scripts/cpu-accounting.sh scripts/test.sh)
#        output in build/cpu-accounting.log, the report in build/cpu-accounting.txt
set -uo pipefail
cd "$(dirname "$0")/.."
(($#)) || { echo "usage: $0 COMMAND..." >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "process accounting needs root (accton)" >&2; exit 2; }
source scripts/packages.sh
kf_install_missing acct
mkdir -p build
records=$PWD/build/cpu-accounting.pacct
rm -f "$records" && touch "$records"
accton "$records" > /dev/null || exit 1
# Off however the command ends (Ctrl-C included): the kernel would go on writing to the file.
trap 'accton off > /dev/null' EXIT
"$@" 2>&1 | tee build/cpu-accounting.log
code=${PIPESTATUS[0]}
accton off > /dev/null
trap - EXIT
dump-acct "$records" | /usr/bin/python3 scripts/accounting/report.py build/cpu-accounting.log > build/cpu-accounting.txt
echo "== CPU by process and by test: build/cpu-accounting.txt"
head -30 build/cpu-accounting.txt
exit "$code"
