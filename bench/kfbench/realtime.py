"""Realtime parts: scsynth booted by sclang against `jackd -d dummy` (kfharness.jack and
kfharness.sclang.run_with_server: a JACK server of its own per run, teardown by pid).

    e2e    a FrictionPilot synth on FrictionDevice.sim (device thread, realtime) for a while, then
           kfStatus: the 1 kHz loop's period, report-to-UGen and force-to-magnet latencies
    scale  voices of the pilot chain on one simulated device: the most whose every window has no
           xrun (JACK: scsynth did not finish a period in time), by a search that re-tests its
           answer, three times; then once with 1 % of the periods allowed to be missed
"""
import re
import time

from kfharness import jack, profile, sclang

from . import scores
from .common import MAPPING, MAPPINGS, PILOT_FRAMES, log

SIGNAL_MM = PILOT_FRAMES // MAPPINGS[0]  # the pilot signal's length at mapping 1
MEASURES = ("loop period", "report to UGen", "force to magnet")
STATUS_RE = re.compile(r"kfStatus 0: (loop period|report to UGen|force to magnet) p50 ([0-9.]+) ms, "
                       r"p99 ([0-9.]+) ms, max ([0-9.]+) ms \(n (\d+)\)")
REALTIME_PRIORITY = 70  # jackd -R -P 70 for the scale part, as a performer would run it
SCALE_SERVER_OPTIONS = {"memSize": 524288, "maxNodes": 32768}  # one DelayL buffer per voice


def parse_status(output):
    out = {}
    for m in STATUS_RE.finditer(output):
        out[m.group(1)] = {"p50_ms": float(m.group(2)), "p99_ms": float(m.group(3)), "max_ms": float(m.group(4)),
                           "n": int(m.group(5))}
    m = re.search(r"kfStatus 0: (\w+), reports (\d+) .*frames (\d+),.*queue overflows (\d+)/(\d+)", output)
    if m:
        out["mode"] = m.group(1)
        out["reports"] = int(m.group(2))
        out["frames"] = int(m.group(3))
        out["overflows"] = [int(m.group(4)), int(m.group(5))]
    return out


def client_xruns(log_text):
    """JACK's `client = SuperCollider was not finished` lines: scsynth missed a period."""
    return log_text.count("was not finished")


def driver_xruns(log_text):
    return len(re.findall(r"JackTimedDriver::Process XRun", log_text))


def _failed(what, run):
    raise SystemExit(f"{what} failed, log {run.log_path}:\n{run.output[-4000:]}")


def run_e2e(bench, seconds=10.0, sample_rate=48000):
    code = scores.code("e2e", cycles=int(seconds) + 2, seconds=seconds, len_mm=SIGNAL_MM)
    with jack.JackServer(sample_rate=sample_rate) as server:
        t = time.monotonic()
        run = sclang.run_with_server(code, server, timeout=seconds + 60, name="bench-e2e",
                                     include_paths=bench.include_paths)
        jack_log = server.log_path.read_text(errors="replace")
    if not run.ok:
        _failed("e2e run", run)
    status = parse_status(run.output)
    for k in MEASURES:
        if k not in status:
            raise SystemExit(f"e2e: no '{k}' line from kfStatus:\n{run.output[-4000:]}")
    m = re.search(r"KF-E2E-CPU ([0-9.e+-]+) ([0-9.e+-]+)", run.output)
    status["peak_cpu"], status["avg_cpu"] = (float(m.group(1)), float(m.group(2))) if m else (None, None)
    status["client_xruns"] = client_xruns(jack_log)
    status["driver_xruns"] = driver_xruns(jack_log)
    status["seconds"] = seconds
    status["wall_s"] = time.monotonic() - t
    log(f"e2e: loop period p50 {status['loop period']['p50_ms']:.3f} p99 {status['loop period']['p99_ms']:.3f} "
        f"max {status['loop period']['max_ms']:.3f} ms; report to UGen p99 {status['report to UGen']['p99_ms']:.3f} ms; "
        f"force to magnet p99 {status['force to magnet']['p99_ms']:.3f} ms; xruns {status['client_xruns']}")
    return status


def run_scale(bench, sample_rate, window_s=2.0, settle_s=0.75, max_voices=8192, budget_s=300.0, realtime=True,
              xrun_fraction=0.0, repeats=3):
    """The largest count of voices whose every window (`repeats` of them per step) has no more than
    xrun_fraction of its periods missed, by a search that re-tests its own answer (scale.scd)."""
    priority = REALTIME_PRIORITY if realtime else None
    with jack.JackServer(sample_rate=sample_rate, realtime_priority=priority) as server:
        code = scores.code("scale", jack_log=sclang.sc_string(server.log_path), window=window_s, settle=settle_s,
                           max_voices=max_voices, budget=budget_s, xrun_fraction=xrun_fraction, repeats=repeats,
                           len_mm=SIGNAL_MM, spm=MAPPINGS[0], mappings=MAPPINGS, window_s=MAPPING["windowS"],
                           lo_db=MAPPING["loDb"], hi_db=MAPPING["hiDb"], lo_force_n=MAPPING["loForceN"],
                           hi_force_n=MAPPING["hiForceN"], ref=MAPPING["ref"],
                           audio_delay_s=round(profile.audio_delay_s(), 9))
        t = time.monotonic()
        # The search stops itself after budget_s; the margin is for a loaded machine (sclang starved
        # by a SCHED_FIFO scsynth at full load on one core and the other busy) to finish and quit.
        run = sclang.run_with_server(code, server, timeout=2 * budget_s + 90, name=f"bench-scale-{sample_rate}",
                                     include_paths=bench.include_paths, server_options=SCALE_SERVER_OPTIONS)
    if not run.ok:
        _failed(f"scale run at {sample_rate} Hz", run)
    steps = [{"voices": int(f[0]), "window_xruns": [int(x) for x in f[1:4] if int(x) >= 0],
              "driver_xruns": int(f[4]), "peak_cpu": float(f[5]), "avg_cpu": float(f[6])}
             for f in run.lines("KF-SCALE ")]
    res, check = run.lines("KF-SCALE-RESULT "), run.lines("KF-SCALE-CHECK ")
    if not res or not check:
        _failed(f"scale run at {sample_rate} Hz (no result)", run)
    lo, hi = int(res[0][0]), int(res[0][1])
    out = {"sample_rate": sample_rate, "window_s": window_s, "settle_s": settle_s, "repeats": repeats,
           "steps": steps, "realtime_jack": realtime, "xrun_fraction": xrun_fraction,
           "xrun_limit": int(run.lines("KF-SCALE-LIMIT ")[0][0]),
           "max_without_xrun": lo, "first_with_xrun": hi if hi >= 0 else None,
           # the search's own check: its answer re-tested (1) or the budget ran out first (0), and
           # how many re-tests contradicted an earlier one
           "confirmed": check[0][0] == "1", "reversals": int(check[0][1]),
           "capped": bool(run.lines("KF-SCALE-CAP")), "wall_s": time.monotonic() - t,
           # the step at which scsynth stopped answering /sync (JACK no longer ran it), if any
           "unresponsive_at": next((int(f[0]) for f in run.lines("KF-SCALE-UNRESPONSIVE ")), None)}
    log(f"scale {sample_rate} Hz, at most {out['xrun_limit']} xruns a window: {lo} voices, first failing "
        f"{out['first_with_xrun']} ({len(steps)} steps, {out['reversals']} reversals, "
        f"{'confirmed' if out['confirmed'] else 'NOT confirmed'}, {out['wall_s']:.0f} s)")
    return out


def run_scale_searches(bench, rate, runs, tolerant_fraction=0.01):
    """`runs` searches at one rate for the count without any xrun; the reported count is the one
    every search reached (their minimum: it passed each time), the median search in full beside
    it. Then one search at tolerant_fraction of missed periods: what the VM carries if the misses
    its own scheduling causes at any load are let through."""
    found = []
    for i in range(runs):
        log(f"scale at {rate} Hz without xruns, search {i + 1} of {runs}")
        found.append(run_scale(bench, rate))
    best = dict(sorted(found, key=lambda r: r["max_without_xrun"])[(len(found) - 1) // 2])
    best["all_runs"] = [r["max_without_xrun"] for r in found]
    best["in_every_search"] = min(best["all_runs"])
    best["all_reversals"] = [r["reversals"] for r in found]
    best["all_confirmed"] = all(r["confirmed"] for r in found)
    log(f"scale at {rate} Hz with {100 * tolerant_fraction:g} % of periods missed allowed")
    best["tolerant"] = run_scale(bench, rate, xrun_fraction=tolerant_fraction)
    return best
