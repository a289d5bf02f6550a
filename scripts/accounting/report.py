"""The CPU time in process accounting records (dump-acct's lines on stdin), by process name and,
for each ctest in the log given, by test: scripts/cpu-accounting.sh.

A record names a process by the thread that ended last: sclang's are named after Qt WebEngine's
threads (sandbox_ipc_thr, ThreadPoolForeg...), counted here as sclang. Records carry no arguments,
so a ctest's test is told by its duration: each child of ctest is matched to the test in the log
whose duration is nearest (within 1 s), longest first. Processes are told apart by pid: a run of
more processes than pid_max (32768 here) may join two into one tree."""
import collections
import re
import sys

TICKS_PER_S = 100  # dump-acct's times
SCLANG_NAMES = {"sclang", "sandbox_ipc_thr", "ThreadPoolForeg", "ThreadPoolServi", "inotify_reader",
                "CompositorTileW", "VizCompositorTh", "VideoCaptureThr", "Chrome_IOThread", "QXcbEventQueue",
                "llvmpipe-0", "QtWebEngineProc"}


def records(lines):
    """(name, cpu s, elapsed s, pid, ppid) of each record: command|version|user|system|elapsed|uid|
    gid|memory|io|pid|ppid|flags|exit|tty|start (the name may hold a '|', so counted from the end)."""
    for line in lines:
        f = [x.strip() for x in line.split("|")]
        if len(f) < 15:
            continue
        name = "|".join(f[:-14])
        yield (name, (float(f[-13]) + float(f[-12])) / TICKS_PER_S, float(f[-11]) / TICKS_PER_S, int(f[-6]), int(f[-5]))


def logged_tests(log_path):
    """Each ctest's tests in the log: lists of (name, seconds), one list per ctest run."""
    runs, current = [], None
    for line in open(log_path, errors="replace"):
        if re.match(r"\s*Test project ", line):
            current = []
            runs.append(current)
        m = re.match(r"\s*\d+/\d+ Test\s+#\d+: (.+?) \.+\s*\**[^0-9]*?\s([\d.]+) sec", line)
        if m and current is not None:
            current.append((m.group(1), float(m.group(2))))
    return runs


def by_test(recs, ctest_pid, tests):
    """CPU s per test: each child of ctest with everything below it, matched to a test by duration."""
    parent = {pid: ppid for _, _, _, pid, ppid in recs}
    top = {}

    def child_of_ctest(pid):
        seen = 0
        while pid in parent and parent[pid] != ctest_pid and seen < 64:
            pid, seen = parent[pid], seen + 1
        return pid if parent.get(pid) == ctest_pid else None

    cpu = collections.defaultdict(float)
    for name, seconds, _, pid, _ in recs:
        child = top.setdefault(pid, child_of_ctest(pid))
        if child is not None:
            cpu[child] += seconds
    elapsed = {pid: e for _, _, e, pid, _ in recs}
    unused, rows = dict(enumerate(tests)), []
    for child in sorted(cpu, key=lambda p: -elapsed.get(p, 0)):
        near = min(unused, key=lambda i: abs(unused[i][1] - elapsed.get(child, 0)), default=None)
        name = "?"
        if near is not None and abs(unused[near][1] - elapsed.get(child, 0)) < 1.0:
            name = unused.pop(near)[0]
        rows.append((cpu[child], elapsed.get(child, 0), name))
    return sorted(rows, reverse=True)


def main():
    recs = list(records(sys.stdin))
    total = collections.defaultdict(lambda: [0.0, 0])
    for name, seconds, _, _, _ in recs:
        key = "sclang (and Qt WebEngine)" if name in SCLANG_NAMES else name
        total[key][0] += seconds
        total[key][1] += 1
    print(f"{sum(r[1] for r in recs):.0f} CPU-s in {len(recs)} processes\n\nCPU-s  processes  name")
    for name, (seconds, count) in sorted(total.items(), key=lambda kv: -kv[1][0])[:30]:
        print(f"{seconds:7.1f} {count:9d}  {name}")
    ctests = [(pid, e) for name, _, e, pid, _ in recs if name == "ctest"]
    for (pid, elapsed), tests in zip(ctests, logged_tests(sys.argv[1]) if len(sys.argv) > 1 else []):
        rows = by_test(recs, pid, tests)
        groups = collections.defaultdict(lambda: [0.0, 0.0, 0])
        for seconds, test_s, name in rows:
            parts = name.split("/")
            g = groups["/".join(parts[:2] if parts[0] in ("sanitized", "cross") else parts[:1])]
            g[0], g[1], g[2] = g[0] + seconds, g[1] + test_s, g[2] + 1
        print(f"\nctest (pid {pid}, {elapsed:.0f} s): CPU-s by group, then by test\nCPU-s  test-s  tests  group")
        for name, (seconds, test_s, count) in sorted(groups.items(), key=lambda kv: -kv[1][0]):
            print(f"{seconds:7.1f} {test_s:7.1f} {count:5d}  {name}")
        print("\nCPU-s  test-s  test")
        for seconds, test_s, name in rows[:60]:
            print(f"{seconds:7.1f} {test_s:7.1f}  {name}")


if __name__ == "__main__":
    main()
