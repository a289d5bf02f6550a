"""Soak: realtime scsynth on JACK's dummy driver for a long run (not in CI).

Two sessions on one JACK server: a baseline of 8 plain sines, then 8 pilot voices on 8
simulated devices (a FrictionHand going back and forth), a recorder on device 0 and a status
poll of every device. By default as a performer on a busy machine runs it: JACK and the device
threads with realtime scheduling (where this user may), and the load of the bench's loaded
columns (two CPU hogs, a disk writer) for the whole run. Reports scsynth's RSS over time, JACK
xruns of each session, and each device's /kfStatus figures: its threads' scheduling, latency
percentiles, missed deadlines, watchdog trips, lost frames and reports.

Usage: python3 tests/soak/soak.py [--minutes 10] [--baseline-minutes 2] [--no-load] [--normal-priority]
"""
import argparse
import re
import time

from kfharness import load, paths, sclang, status
from kfstudy import readers
from kfharness.witness import Witness
from kfharness.jack import JackServer

REALTIME_PRIORITY = 70  # jackd -R -P 70, as the realtime tests and the bench run it

VOICES = 8

# /proc files report size 0, so File.readAllString sees nothing: ps reads VmRSS for us.
RSS_POLL = r"""
~rssOf = { |pid| "ps -o rss= -p %".format(pid).unixCmdGetStdOut.asInteger };
"""


def xruns(jack):
    return len(re.findall(r"xrun", jack.log_path.read_text(errors="replace"), re.I))


def baseline(jack, seconds):
    code = "var synths, t0 = Main.elapsedTime;\n" + RSS_POLL + f"""
        synths = {VOICES}.collect {{ |i| {{ SinOsc.ar(220 * (i + 1), 0, 0.05) }}.play }};
        s.sync;
        while {{ Main.elapsedTime - t0 < {seconds} }} {{
            "KF-RSS % %\n".postf(Main.elapsedTime - t0, ~rssOf.(s.pid));
            "KF-CPU % % %\n".postf(Main.elapsedTime - t0, s.avgCPU, s.peakCPU);
            10.wait;
        }};
        synths.do(_.free);
    """
    return sclang.require_ok(sclang.run_with_server(code, jack, name="soak-baseline", timeout=seconds + 120), "baseline")


def devices(jack, seconds, record, thread_priority):
    segments = max(2, int(seconds / 2) + 4)
    hand = ", ".join("[50, 1], [-50, 1]" for _ in range(segments // 2))
    code = "var devs, pilots, t0;\n" + RSS_POLL + status.SC_POST + f"""
        devs = {VOICES}.collect {{ |i|
            FrictionDevice.sim(s, i, FrictionHand.speeds([{hand}]), (threadPriority: {thread_priority}))
        }};
        s.sync;
        devs[0].record({sclang.sc_string(record)});
        pilots = devs.collect {{ |d, i| FrictionPilot(d, [\\mapping1, \\mapping2, \\mapping3].wrapAt(i), 1, 0, 0.05).play }};
        s.sync;
        2.wait;
        t0 = Main.elapsedTime;
        while {{ Main.elapsedTime - t0 < {seconds} }} {{
            "KF-RSS % %\n".postf(Main.elapsedTime - t0, ~rssOf.(s.pid));
            "KF-CPU % % %\n".postf(Main.elapsedTime - t0, s.avgCPU, s.peakCPU);
            devs.do(_.status);
            10.wait;
        }};
        devs.do {{ |d| ~kfPostStatus.(d, "KF-STATUS") }};
        1.wait;
        pilots.do(_.free);
        devs[0].stopRecording;
        devs.do(_.close);
        s.sync;
    """
    return sclang.require_ok(sclang.run_with_server(code, jack, name="soak-devices", timeout=seconds + 180), "devices")


def series(run, tag):
    return [[float(v) for v in fields] for fields in run.lines(tag)]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--baseline-minutes", type=float, default=2.0)
    parser.add_argument("--no-load", action="store_true", help="without the background load")
    parser.add_argument("--normal-priority", action="store_true",
                        help="JACK and the device threads at normal priority (threadPriority 0)")
    args = parser.parse_args()
    record = paths.work_dir() / "soak-session.txt"
    started = time.monotonic()
    realtime = not args.normal_priority and load.realtime_allowed()
    background = None if args.no_load else load.BackgroundLoad()
    with JackServer(realtime_priority=REALTIME_PRIORITY if realtime else None) as jack:
        if background:
            background.start()
        try:
            x0 = xruns(jack)
            base = baseline(jack, args.baseline_minutes * 60)
            x1 = xruns(jack)
            with Witness() as witness:
                dev = devices(jack, args.minutes * 60, record, -1 if realtime else 0)
            x2 = xruns(jack)
        finally:
            if background:
                background.stop()

    print(f"soak: {args.minutes} min with {VOICES} pilot voices on {VOICES} sim devices, baseline "
          f"{args.baseline_minutes} min of {VOICES} sines (JACK dummy, {48000} Hz, period {64}"
          f"{f', jackd -R -P {REALTIME_PRIORITY}' if realtime else ', normal priority'}); "
          f"load: {background.describe() if background else 'none'}; wall {time.monotonic() - started:.0f} s")
    for name, run, xr, minutes in [("baseline", base, x1 - x0, args.baseline_minutes),
                                   ("devices", dev, x2 - x1, args.minutes)]:
        rss = series(run, "KF-RSS ")
        cpu = series(run, "KF-CPU ")
        print(f"\n[{name}] JACK xruns {xr} ({xr / minutes:.2f}/min)")
        if rss:
            print("  scsynth RSS kB over time: " + ", ".join(f"{t:.0f}s {kb:.0f}" for t, kb in rss))
            print(f"  RSS start {rss[0][1]:.0f} kB, end {rss[-1][1]:.0f} kB, growth {rss[-1][1] - rss[0][1]:+.0f} kB")
        if cpu:
            print(f"  scsynth CPU avg {sum(c[1] for c in cpu) / len(cpu):.1f} %, peak {max(c[2] for c in cpu):.1f} %")
    figures = status.parse(dev.output, "KF-STATUS")
    print("\n[devices] each device's /kfStatus at the end: device thread priority (0 normal), reports, frames, "
          "watchdog trips, missed deadlines, lost reports/frames (queue overflows), frames superseded (the older "
          "frames due at a late wake-up: the newest goes to the magnet); latencies "
          "p50/p99/p99.9/max ms")
    ms = 1e3
    for index in sorted(figures):
        f = figures[index]
        print(f"  {index}: thread {f['deviceThreadPriority']:.0f}, reports {f['reports']:.0f}, frames {f['frames']:.0f}, "
              f"trips {f['watchdogTrips']:.0f}, missed deadlines {f['missedDeadlines']:.0f}, lost "
              f"{f['reportQueueOverflows']:.0f}/{f['frameQueueOverflows']:.0f}, superseded {f['skippedFrames']:.0f}; "
              f"force to magnet {f['forceP50S'] * ms:.3f}/{f['forceP99S'] * ms:.3f}/{f['forceP999S'] * ms:.3f}/"
              f"{f['forceMaxS'] * ms:.3f}; loop period p99 {f['loopP99S'] * ms:.3f} max {f['loopMaxS'] * ms:.3f}; "
              f"report to UGen p99 {f['reportP99S'] * ms:.3f} max {f['reportMaxS'] * ms:.3f}")
    machine = witness.result
    print("  the machine's own wake-up max in the same window (cyclictest, SCHED_FIFO 90 above our threads): "
          + (f"{machine['max_us'] / 1e3:.3f} ms, mean {machine['avg_us']:.0f} us" if machine else "not measured"))
    header, records = readers.read_session(record)
    frames = sum(1 for tag, _ in records if tag == "F")
    print(f"\n[recorder] {record}: {len(records)} records, {frames} frames, last record {records[-1][0]}")


if __name__ == "__main__":
    main()
