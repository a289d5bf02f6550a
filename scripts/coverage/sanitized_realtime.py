"""Which realtime tests add plugin coverage to the sanitized plugin's run: from gcov's data of one
run per test file (and one of all the scene tests, which run against the sanitized plugin too),
written by scripts/sanitized-coverage.sh. A realtime test whose plugin lines the others all run
(scenes included) adds no line for the sanitizers to see; removed one at a time, the longest
first, until each left has lines of its own. Tests whose servers are killed or signalled write
no gcov data (a server writes it at its exit), so they stay whatever their lines. The sanitized run
takes a selection of the help files (a run named help_selection): it stands for test_help_examples,
and the lines the whole help runs that it and the tests kept do not are listed (exit 1).
Usage: sanitized_realtime.py <gcov data folder> <source folder> [kept test...]"""
import glob
import json
import os
import shutil
import subprocess
import sys


def covered_lines(data_dir, source_dirs):
    """(source, line) of every line run at least once, from the .gcda files under data_dir (the
    build's paths under it: GCOV_PREFIX) and the build's .gcno files beside their objects."""
    covered = set()
    for gcda in glob.glob(os.path.join(data_dir, "**", "*.gcda"), recursive=True):
        gcno = gcda[len(data_dir):][:-len(".gcda")] + ".gcno"
        if not os.path.exists(gcno):
            continue
        shutil.copy(gcno, gcda[:-len(".gcda")] + ".gcno")
        out = subprocess.run(["gcov", "--stdout", "--json-format", gcda], capture_output=True, text=True,
                             cwd=data_dir).stdout
        for chunk in filter(lambda line: line.startswith("{"), out.splitlines()):
            report = json.loads(chunk)
            for source in report["files"]:
                path = os.path.normpath(os.path.join(report.get("current_working_directory", "/"), source["file"]))
                if path.startswith(source_dirs):
                    covered.update((path, line["line_number"]) for line in source["lines"] if line["count"] > 0)
    return covered


def main():
    data_root, source_dir, *kept = sys.argv[1:]
    sources = tuple(os.path.join(source_dir, d) + os.sep for d in ("dsp", "device", "host", "plugins"))
    coverage = {name: covered_lines(os.path.join(data_root, name), sources) for name in sorted(os.listdir(data_root))}
    seconds = {}
    for name in coverage:
        log = os.path.join(data_root, "..", f"{name}.seconds")
        seconds[name] = float(open(log).read()) if os.path.exists(log) else 0.0
    # The sanitized run takes a selection of the help files (help_selection): it stands for
    # test_help_examples there; every line the whole help runs must still be run.
    whole_help = coverage.get("test_help_examples", set())
    if "help_selection" in coverage:
        coverage["test_help_examples"] = coverage.pop("help_selection")
        seconds["test_help_examples"] = seconds.pop("help_selection", 0.0)
        kept = kept + ["test_help_examples"]
    running = set(coverage)
    for name in sorted(coverage, key=lambda n: -len(coverage[n])):
        print(f"{name:32s} {len(coverage[name]):5d} lines {seconds[name]:6.0f} s")
    while True:
        removable = [name for name in running - set(kept) - {"scenes"}
                     if not coverage[name] - set().union(*(coverage[o] for o in running if o != name))]
        if not removable:
            break
        longest = max(removable, key=lambda n: seconds[n])
        running.remove(longest)
        print(f"no line of its own: {longest} ({seconds[longest]:.0f} s)")
    union = set().union(*coverage.values())
    print(f"plugin lines run: {len(union)}; the sanitized run keeps: {' '.join(sorted(running - {'scenes'}))}")
    missed = sorted(whole_help - set().union(*(coverage[name] for name in running)))
    if missed:
        print(f"the help files' selection (tests/realtime/sanitized-help-files.txt) misses {len(missed)} lines the "
              f"whole help runs: add the files that run them:")
        for path, line in missed:
            print(f"  {os.path.relpath(path, source_dir)}:{line}")
        sys.exit(1)


if __name__ == "__main__":
    main()
