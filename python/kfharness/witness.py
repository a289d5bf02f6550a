"""The machine's own wake-up latency, measured in the window of a run: cyclictest (Debian
rt-tests), one SCHED_FIFO 90 thread per core, above every thread of ours, waking every 1 ms with
its memory locked. How late it woke is how long the machine (on a virtual machine, the host
pausing a vCPU) kept even the highest priority from running; a stall of ours longer than that
in the same window is ours.

    with Witness() as w:
        ...run...
    w.result  # {"max_us": ..., "avg_us": ..., "stalls": ...} or None without cyclictest

stalls: how many times the machine kept the witness from running for longer than `stall_us` (the
most over its threads, one a core: a stall of the machine holds them all). After a late wake-up
cyclictest sleeps to its next deadline still ahead, so one stall counts once however long it was.

Witness(normal_priority=True), for a user without realtime scheduling (cyclictest refuses to run
there: it always asks for SCHED_FIFO): one thread at normal priority (SCHED_OTHER, as our threads
then run), waking every 1 ms to absolute deadlines, measures how long a normal thread waited for
the CPU beside whatever else runs (the scheduler's share, not only the machine's stalls). Same
result; a Python thread, so its figures include some 50 us of its own.
"""
import re
import shutil
import signal
import subprocess
import sys

# The normal-priority witness: sleeps to 1 ms deadlines until SIGINT, then prints the lateness
# in cyclictest's summary lines (us), so that one parser reads both.
NORMAL_SAMPLER = r"""
import signal, sys, time
stall_us, period = int(sys.argv[1]), 0.001
stop, total, count, worst, stalls = [], 0.0, 0, 0.0, 0
signal.signal(signal.SIGINT, lambda *_: stop.append(1))
deadline = time.monotonic()
while not stop:
    deadline += period
    ahead = deadline - time.monotonic()
    if ahead > 0:
        time.sleep(ahead)
    late = time.monotonic() - deadline
    total, count, worst, stalls = total + late, count + 1, max(worst, late), stalls + (late * 1e6 > stall_us)
    if late >= period:  # as cyclictest: on to the next deadline still ahead, no catching up
        deadline += late // period * period
print("# Avg Latencies: %d" % (total / max(count, 1) * 1e6))
print("# Max Latencies: %d" % (worst * 1e6))
print("# Histogram Overflows: %d" % stalls)
"""


def summary(output):
    """{"max_us", "avg_us", "stalls", "p99_us"} from cyclictest's (or NORMAL_SAMPLER's) summary
    lines, or None: the worst and the mean wake-up latency over the threads, the most stalls of any
    thread, and the 99th percentile of every thread's wake-ups together from cyclictest's histogram
    (1 us bins; None without one: the normal-priority sampler keeps none)."""
    def values(name):
        m = re.search(rf"^# {name}: ([\d ]+)$", output, re.M)
        return [int(v) for v in m.group(1).split()] if m else []
    maxima, means, overflows = values("Max Latencies"), values("Avg Latencies"), values("Histogram Overflows")
    if not (maxima and means):
        return None
    return {"max_us": max(maxima), "avg_us": sum(means) / len(means), "stalls": max(overflows or [0]),
            "p99_us": histogram_p99(output, sum(overflows))}


def histogram_p99(output, overflows):
    """The 99th percentile (us) of cyclictest's histogram lines ("<us> <count per thread>..."), the
    wake-ups beyond its range (`overflows`) counted above it; None without a histogram."""
    counts = [(int(m.group(1)), sum(int(c) for c in m.group(2).split()))
              for m in re.finditer(r"^(\d{6}) ((?:\d+[ \t]*)+)$", output, re.M)]
    total = sum(c for _, c in counts) + overflows
    if not counts or total == 0:
        return None
    seen = 0
    for us, count in counts:
        seen += count
        if seen >= 0.99 * total:
            return us
    return None  # the percentile lies beyond the histogram's range


class Witness:
    def __init__(self, stall_us=100000, normal_priority=False):
        self.stall_us = stall_us
        self.normal_priority = normal_priority
        self.proc = None
        self.result = None
        self.output = ""

    def start(self):
        if self.normal_priority:
            self.proc = subprocess.Popen([sys.executable, "-c", NORMAL_SAMPLER, str(self.stall_us)],
                                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        elif shutil.which("cyclictest"):
            self.proc = subprocess.Popen(["cyclictest", "-m", "-p", "90", "-t", "-a", "-i", "1000", "-q",
                                          "-h", str(self.stall_us)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        return self

    def stop(self):
        """Ends the measurement; the max and mean wake-up latency (us) over the cores, or None."""
        if self.proc is None:
            return None
        self.proc.send_signal(signal.SIGINT)  # cyclictest prints its summary on SIGINT
        try:
            self.output = self.proc.communicate(timeout=30)[0]
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.output = self.proc.communicate()[0]
        self.proc = None
        self.result = summary(self.output)
        return self.result

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
