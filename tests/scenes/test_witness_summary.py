"""The witness's reading of cyclictest's summary (kfharness.witness): its stall count once read
no line at all (it looked for "# Histogram Overflows Latencies:"), so every realtime test that
weighed watchdog trips against the machine's stalls saw none."""
import os
import signal
import time

from kfharness.witness import Witness, summary

# cyclictest 2.40's summary after -q -h 300 on two threads (measured here beside two CPU hogs).
CYCLICTEST = """# /dev/cpu_dma_latency set to 0us
# Histogram
000000 000000\t000000
# Total: 000004997 000004989
# Min Latencies: 00006 00005
# Avg Latencies: 00014 00013
# Max Latencies: 00580 02121
# Histogram Overflows: 00004 00008
# Histogram Overflow at cycle number:
# Thread 0: 00057 00087 00099 00118
# Thread 1: 00004 00056 00138 00147 00171 00180 00202 00224
"""


def test_the_summary_gives_the_worst_latency_the_mean_and_the_most_stalls_of_a_thread():
    # Every wake-up counted is beyond the histogram's one bin: its 99th percentile is out of range.
    assert summary(CYCLICTEST) == {"max_us": 2121, "avg_us": 13.5, "stalls": 8, "p99_us": None}
    assert summary("cyclictest: no summary") is None


def test_the_99th_percentile_is_of_every_threads_wake_ups_together_overflows_above_the_range():
    # 1000 wake-ups: 900 at 10 us, 85 at 11 us (985), 5 at 12 us (990: the 99th percentile), 8 at
    # 13 us and 2 beyond the range (one a thread).
    lines = ["# Histogram", "000010 000450\t000450", "000011 000040\t000045", "000012 000005\t000000",
             "000013 000004\t000004", "# Min Latencies: 00010 00010", "# Avg Latencies: 00010 00010",
             "# Max Latencies: 00200 00300", "# Histogram Overflows: 00001 00001"]
    assert summary("\n".join(lines) + "\n")["p99_us"] == 12
    lines[3] = "000012 000004\t000000"  # 989 up to 12 us: the 99th percentile is the next bin's
    assert summary("\n".join(lines) + "\n")["p99_us"] == 13


def test_a_witness_held_longer_than_its_threshold_counts_the_stall():
    # The normal-priority sampler (it needs no realtime rights), held 0.2 s by SIGSTOP once it has
    # started: at least that stall (another of 50 ms on a busy machine may add one).
    with Witness(stall_us=50000, normal_priority=True) as w:
        time.sleep(0.5)
        os.kill(w.proc.pid, signal.SIGSTOP)
        time.sleep(0.2)
        os.kill(w.proc.pid, signal.SIGCONT)
        time.sleep(0.3)
    assert w.result["stalls"] >= 1 and w.result["max_us"] >= 190000, w.result
