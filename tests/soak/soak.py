"""Soak: realtime scsynth on JACK's dummy driver for a long run (issue 13, not in CI).

Two sessions on one JACK server: a baseline of 8 plain sines, then 8 pilot voices on 8
simulated devices (a FrictionHand going back and forth), a recorder on device 0 and a status
poll of every device. Reports scsynth's RSS over time, JACK xruns of each session, the device
threads' latency percentiles and lost frames/reports (queue overflows) from kfStatus.

Usage: python3 tests/soak/soak.py [--minutes 10] [--baseline-minutes 2]
"""
import argparse
import re
import time

from kfharness import paths, readers, sclang
from kfharness.jack import JackServer

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
            "KF-RSS % %".format(Main.elapsedTime - t0, ~rssOf.(s.pid)).postln;
            "KF-CPU % % %".format(Main.elapsedTime - t0, s.avgCPU, s.peakCPU).postln;
            10.wait;
        }};
        synths.do(_.free);
    """
    return sclang.require_ok(sclang.run_with_server(code, jack, name="soak-baseline", timeout=seconds + 120), "baseline")


def devices(jack, seconds, record):
    segments = max(2, int(seconds / 2) + 4)
    hand = ", ".join("[50, 1], [-50, 1]" for _ in range(segments // 2))
    code = "var devs, pilots, t0;\n" + RSS_POLL + f"""
        devs = {VOICES}.collect {{ |i| FrictionDevice.sim(s, i, FrictionHand.speeds([{hand}])) }};
        s.sync;
        devs[0].record({sclang.sc_string(record)});
        pilots = devs.collect {{ |d, i| FrictionPilot(d, [\\mapping1, \\mapping2, \\mapping3].wrapAt(i), 1, 0, 0.05).play }};
        s.sync;
        2.wait;
        t0 = Main.elapsedTime;
        while {{ Main.elapsedTime - t0 < {seconds} }} {{
            "KF-RSS % %".format(Main.elapsedTime - t0, ~rssOf.(s.pid)).postln;
            "KF-CPU % % %".format(Main.elapsedTime - t0, s.avgCPU, s.peakCPU).postln;
            devs.do(_.status);
            10.wait;
        }};
        devs.do(_.status);
        s.sync;
        1.wait;
        pilots.do(_.free);
        devs[0].stopRecording;
        devs.do(_.close);
        s.sync;
    """
    return sclang.require_ok(sclang.run_with_server(code, jack, name="soak-devices", timeout=seconds + 180), "devices")


def series(run, tag):
    return [[float(v) for v in fields] for fields in run.lines(tag)]


def last_status(run):
    """The last kfStatus lines of each device: {index: {field: value}}."""
    status = {}
    for line in run.output.splitlines():
        m = re.match(r"kfStatus (\d+): (realtime|lockstep), reports (\d+) .*frames (\d+), .*watchdog trips (\d+), "
                     r"queue overflows (\d+)/(\d+)", line)
        if m:
            status.setdefault(int(m.group(1)), {}).update(
                reports=int(m.group(3)), frames=int(m.group(4)), trips=int(m.group(5)),
                reportOverflows=int(m.group(6)), frameOverflows=int(m.group(7)))
        m = re.match(r"kfStatus (\d+): (loop period|report to UGen|force to magnet) p50 ([\d.]+) ms, p99 ([\d.]+) ms, "
                     r"max ([\d.]+) ms", line)
        if m:
            status.setdefault(int(m.group(1)), {})[m.group(2)] = tuple(float(m.group(i)) for i in (3, 4, 5))
    return status


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--baseline-minutes", type=float, default=2.0)
    args = parser.parse_args()
    record = paths.work_dir() / "soak-session.txt"
    started = time.monotonic()
    with JackServer() as jack:
        x0 = xruns(jack)
        base = baseline(jack, args.baseline_minutes * 60)
        x1 = xruns(jack)
        dev = devices(jack, args.minutes * 60, record)
        x2 = xruns(jack)

    print(f"soak: {args.minutes} min with {VOICES} pilot voices on {VOICES} sim devices, baseline "
          f"{args.baseline_minutes} min of {VOICES} sines (JACK dummy, {48000} Hz, period {64}); "
          f"wall {time.monotonic() - started:.0f} s")
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
    status = last_status(dev)
    print("\n[devices] last kfStatus per device: reports, frames, watchdog trips, lost reports/frames "
          "(queue overflows); latencies p50/p99/max ms")
    for index in sorted(status):
        s = status[index]
        lat = "; ".join(f"{k} {v[0]:.3f}/{v[1]:.3f}/{v[2]:.3f}" for k, v in s.items() if isinstance(v, tuple))
        print(f"  {index}: reports {s.get('reports')}, frames {s.get('frames')}, trips {s.get('trips')}, "
              f"lost {s.get('reportOverflows')}/{s.get('frameOverflows')}; {lat}")
    header, records = readers.read_session(record)
    frames = sum(1 for tag, _ in records if tag == "F")
    print(f"\n[recorder] {record}: {len(records)} records, {frames} frames, last record {records[-1][0]}")


if __name__ == "__main__":
    main()
