"""The device side as a realtime citizen: the force path and the report path measured with
realtime scheduling and no load, with realtime scheduling under the load of a busy machine (two
CPU hogs at normal priority and a disk writer, kfharness.load), and at normal priority under the
same load, side by side in one run, at 48 kHz with 64- and 256-sample periods and at 192 kHz.

Each run: jackd -d dummy (-R -P 70 with realtime scheduling), scsynth booted by sclang, a
FrictionPilot on a simulated device (slot 0) and a FrictionMouseIn on a replayed 1 kHz mouse
(slot 1), `seconds` long; then each device's /kfStatus reply (numbers, FrictionDevice.statusOf).
"""
import re
import time

from kfharness import jack, load, paths, sclang, status
from kfharness.witness import Witness

from . import scores
from .common import log
from .realtime import REALTIME_PRIORITY, SIGNAL_MM, client_xruns, driver_xruns

CONFIGS = [(48000, 64), (48000, 256), (192000, 256)]
CONDITIONS = [  # name, realtime scheduling, background load
    ("realtime", True, False),
    ("realtime, loaded", True, True),
    ("normal priority, loaded", False, True),
]
HID = "genius-gila-gaming-mouse-0458-0138.hid"


def thread_faults(output):
    """{thread name: (minor, major)}: each server thread's page faults from the device's open to the
    run's end (rtload.scd posts /proc's counts at both; threads of one name summed)."""
    seen = {}
    for when, name, minor, major in re.findall(r"^KF-RTLOAD-FAULTS (open|end) (\S+) (\d+) (\d+)$", output, re.M):
        counts = seen.setdefault(name, {"open": [0, 0], "end": [0, 0]})[when]
        counts[0] += int(minor)
        counts[1] += int(major)
    return {name: (w["end"][0] - w["open"][0], w["end"][1] - w["open"][1]) for name, w in seen.items()}


def run_one(bench, sample_rate, period, realtime, loaded, seconds):
    code = scores.code("rtload", post_status=status.SC_POST, cycles=int(seconds) + 2, seconds=seconds, len_mm=SIGNAL_MM,
                       priority=-1 if realtime else 0,
                       hid=sclang.sc_string(paths.test_data_dir() / "hid" / HID))
    priority = REALTIME_PRIORITY if realtime else None
    t = time.monotonic()
    background = load.BackgroundLoad(cpu_hogs=2, disk_writer=True) if loaded else None
    with jack.JackServer(sample_rate=sample_rate, period=period, realtime_priority=priority) as server:
        if background:
            background.start()
        witness = Witness().start()
        try:
            run = sclang.run_with_server(code, server, timeout=seconds + 90, name="bench-rtload",
                                         include_paths=bench.include_paths)
        finally:
            witnessed = witness.stop()
            if background:
                background.stop()
        jack_log = server.log_path.read_text(errors="replace")
    if not run.ok:
        raise SystemExit(f"rtload run failed, log {run.log_path}:\n{run.output[-4000:]}")
    figures = status.parse(run.output, "KF-RTLOAD-STATUS")
    if set(figures) != {0, 1}:
        raise SystemExit(f"rtload: no /kfStatus figures for both devices:\n{run.output[-4000:]}")
    return {"rate": sample_rate, "period": period, "realtime": realtime, "loaded": loaded, "seconds": seconds,
            "force": figures[0], "mouse": figures[1], "faults": thread_faults(run.output),
            "client_xruns": client_xruns(jack_log),
            "driver_xruns": driver_xruns(jack_log), "witness": witnessed, "wall_s": time.monotonic() - t}


def machine_ms(run, key):
    """The witness's figure (us) in ms as text, "-" when not measured."""
    value = (run.get("witness") or {}).get(key)
    return "-" if value is None else f"{value / 1e3:.3f}"


def run_all(bench, seconds=20.0):
    if not load.realtime_allowed():
        log("rtload: this user may not use realtime scheduling; the realtime columns are measured without it")
    runs = []
    for rate, period in CONFIGS:
        for name, realtime, loaded in CONDITIONS:
            log(f"rtload: {rate} Hz / {period}, {name} ({seconds:.0f} s)")
            r = run_one(bench, rate, period, realtime, loaded, seconds)
            r["condition"] = name
            f, m = r["force"], r["mouse"]
            log(f"  force p50 {f['forceP50S'] * 1e3:.3f} p99 {f['forceP99S'] * 1e3:.3f} "
                f"max {f['forceMaxS'] * 1e3:.3f} ms; loop p99 {f['loopP99S'] * 1e3:.3f} ms; missed deadlines "
                f"{f['missedDeadlines']:.0f}; skipped {f['skippedFrames']:.0f}; watchdog {f['watchdogTrips']:.0f}; "
                f"report to UGen p99 {m['reportP99S'] * 1e3:.3f} ms; device thread priority "
                f"{f['deviceThreadPriority']:.0f}, page faults (minor, major) {r['faults'].get('kf-device-0')}; the "
                f"machine's own wake-up in the same window p99 {machine_ms(r, 'p99_us')} max {machine_ms(r, 'max_us')} ms")
            runs.append(r)
    return {"runs": runs, "seconds": seconds, "load": load.BackgroundLoad().describe(),
            "jack_priority": REALTIME_PRIORITY}
