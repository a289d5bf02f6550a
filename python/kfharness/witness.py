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
"""
import re
import shutil
import signal
import subprocess


class Witness:
    def __init__(self, stall_us=100000):
        self.stall_us = stall_us
        self.proc = None
        self.result = None
        self.output = ""

    def start(self):
        if shutil.which("cyclictest"):
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
        maxima, means = self._values("Max"), self._values("Avg")
        overflows = self._values("Histogram Overflows")
        self.result = ({"max_us": max(maxima), "avg_us": sum(means) / len(means), "stalls": max(overflows or [0])}
                       if maxima and means else None)
        return self.result

    def _values(self, name):
        m = re.search(rf"^# {name} Latencies: ([\d ]+)$", self.output, re.M)
        return [int(v) for v in m.group(1).split()] if m else []

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
