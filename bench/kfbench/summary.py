"""The summary the run prints (and the report quotes), and the headline numbers with their spread
over the repeated measurements of the run."""
import numpy as np

from .common import BLOCK, MAPPING, MAPPINGS, SR, fmt
from . import drive_path, patterns, report_rate, texture_rate, thresholds
from .native import reconstruction_checks
from .timing import READERS

DRIFT_TEST_RATE_HZ = 192000  # the Catch2 drift test's window: equation (1)'s at 192 kHz


def _drift_test_n():
    return round(DRIFT_TEST_RATE_HZ * MAPPING["windowS"])


def summary_lines(results):
    """The lines run.py prints at the end and REPORT.md quotes."""
    lines = []
    tm = results.get("timing")
    sp = results.get("spatial")
    ld = results.get("loudness")
    if tm:
        lines.append(f"timing: {tm['instances']} instances x {tm['rounds']} rounds of {tm['phase_s']} s phases, "
                     f"{SR // 1000} kHz, block {BLOCK}; the cores' {tm.get('core_path', '?')} code path on "
                     f"{tm.get('processor', '?')}")
        for label, e in tm["ratios"].items():
            c, w, cs = e["cpu-empty"], e["wall-empty"], e["cpu-source"]
            lines.append(f"  {label:38s} CPU {c['median']:.3f}x [{c['min']:.3f}..{c['max']:.3f}]  "
                         f"wall {w['median']:.3f}x  | source subtracted: CPU {cs['median']:.3f}x [{cs['min']:.3f}..{cs['max']:.3f}]")
        lines.append("  CPU ns per instance-sample (median, minus the empty phase): " + ", ".join(
            f"{n} {np.median(v):.2f}" for n, v in tm["ns"]["cpu"].items()))
        if "vs_bufrd4" in tm:
            lines.append("  CPU / BufRd cubic: " + ", ".join(
                f"{label} {tm['vs_bufrd4'][n]['cpu-empty']['median']:.3f}x "
                f"[{tm['vs_bufrd4'][n]['cpu-empty']['min']:.3f}..{tm['vs_bufrd4'][n]['cpu-empty']['max']:.3f}]"
                for n, label in READERS if n != "bufrd4"))
    if sp:
        for spm in MAPPINGS:
            entries = [e for e in sp["pilot"].values() if e.get("spm") == spm]
            if not entries:
                continue
            parts = [f"{label} {fmt(max(e[label]['max_vs_signal'] for e in entries))}" for _, label in READERS]
            lines.append(f"error vs signal, max over {', '.join(str(e['speed']) for e in entries)} mm/s at {spm} samples/mm: "
                         + ", ".join(parts))
        for label, entry in sp["index"].items():
            parts = []
            for k in ("cubic", "linear"):
                parts.append(f"{k}: SpatialBufRd {fmt(entry['SpatialBufRd ' + k]['max_index_error'])} / BufRd {fmt(entry['BufRd ' + k]['max_index_error'])}")
            parts.append(f"none: wrong sample SpatialBufRd {100 * entry['SpatialBufRd none']['wrong_sample_fraction']:.2f} % / "
                         f"BufRd {100 * entry['BufRd none']['wrong_sample_fraction']:.2f} %")
            lines.append(f"index error (samples, max) {label}: " + "; ".join(parts))
    if ld:
        for name, e in ld["errors"].items():
            lines.append(f"error {name:20s} max {fmt(e['max_n'])} N, rms {fmt(e['rms_n'])} N (vs equations (1), (2) in double)")
    dr = results.get("drift")
    if dr:
        for name in dr["first"]:
            lines.append(f"drift {name:20s} after {dr['minutes']} min: max {fmt(dr['last'][name]['max_n'])} N "
                         f"(first {dr.get('capture_s', 2)} s: {fmt(dr['first'][name]['max_n'])} N)")
    dt = results.get("drift_test")
    if dt:
        lines.append(f"drift LoudnessToFriction core after 10^9 samples (Catch2, n = {_drift_test_n()}): worst {fmt(dt['worst_n'])} N")
    rc = results.get("reconstruction")
    if rc:
        for r in rc["accuracy"]:
            lines.append(f"reconstruction {r['movement']:26s} {r['mode']:10s} lag {r['lagMs']:6.3f} ms, "
                         f"rms error {r['rmsErrorMm']:.5f} mm")
        lines.append("reconstruction CPU ns/sample (median of runs [min..max]): " + ", ".join(
            f"{m} {rc['cpu'][m]:.2f} [{min(v):.2f}..{max(v):.2f}]" for m, v in rc["cpu_runs"].items()))
    if results.get("drive"):
        lines += drive_path.summary_lines(results["drive"])
    if results.get("patterns"):
        lines += patterns.summary_lines(results["patterns"])
    if results.get("texture_rate"):
        lines += texture_rate.summary_lines(results["texture_rate"])
    if results.get("thresholds"):
        lines += thresholds.summary_lines(results["thresholds"])
    rr = results.get("report_rate")
    if rr:
        lines += report_rate.summary_lines(rr)
    e2e = results.get("e2e")
    if e2e:
        for key in ("loop period", "report to UGen", "force to magnet"):
            vals = "; ".join(f"p50 {r[key]['p50_ms']:.3f} p99 {r[key]['p99_ms']:.3f} max {r[key]['max_ms']:.3f}"
                             for r in e2e["runs"])
            lines.append(f"realtime {key:16s} (ms, per run): {vals}")
        lines.append("realtime xruns reported by jackd during the runs: " + ", ".join(
            str(r["client_xruns"]) for r in e2e["runs"]))
    scale = results.get("scale")
    if scale:
        for rate, sc in scale.items():
            tol = sc.get("tolerant")
            lines.append(f"scale {int(rate) // 1000} kHz: {voices(sc.get('in_every_search', sc['max_without_xrun']))} "
                         f"without an xrun in any of {sc.get('repeats', 1)} windows, in every search (searches: "
                         f"{', '.join(str(x) for x in sc.get('all_runs', [sc['max_without_xrun']]))}; reversals "
                         f"{', '.join(str(x) for x in sc.get('all_reversals', []))})"
                         + (f"; {voices(tol['max_without_xrun'])} with up to {100 * tol['xrun_fraction']:g} % of "
                            f"periods missed" if tol else ""))
    lc = results.get("log")
    if lc:
        for r in lc["rows"]:
            if "worst_n" in r:
                lines.append(f"log {r['name']:36s} core {r['core_ns']:.2f} ns/sample, mapping {r['map_ns']:.2f} ns, worst {fmt(r['worst_n'])} N")
            else:
                lines.append(f"log {r['name']:36s} core {r['core_ns']:.2f} ns/sample")
    return lines



def key_numbers(results):
    """The headline numbers with their spread inside this run where there is one:
    label -> (value, spread text, (min, max) or None)."""
    k = {}

    def spread(values, what, digits=3):
        return f"{min(values):.{digits}f}..{max(values):.{digits}f} over {len(values)} {what}", (min(values), max(values))

    tm = results.get("timing")
    if tm:
        for label in tm["ratios"]:
            e = tm["ratios"][label]["cpu-empty"]
            k[f"CPU {label}"] = (e["median"], f"{e['min']:.3f}..{e['max']:.3f} over {tm['rounds']} rounds",
                                 (e["min"], e["max"]))
        for n, label in READERS[:2]:
            e = tm["vs_bufrd4"][n]["cpu-empty"]
            k[f"CPU {label}/BufRd cubic"] = (e["median"], f"{e['min']:.3f}..{e['max']:.3f} over {tm['rounds']} rounds",
                                             (e["min"], e["max"]))
    sp = results.get("spatial")
    if sp:
        k["max error SpatialBufRd cubic vs signal"] = (max(en["SpatialBufRd cubic"]["max_vs_signal"]
                                                        for en in sp["pilot"].values()), "deterministic render", None)
    ld = results.get("loudness")
    if ld:
        k["max error LoudnessToFriction (N)"] = (ld["errors"]["LoudnessToFriction"]["max_n"],
                                                 f"{ld['seconds']:.0f} s of WhiteNoise: a new seed each render", None)
    dt = results.get("drift_test")
    if dt:
        k["drift after 10^9 samples (N)"] = (dt["worst_n"], "deterministic", None)
    rc = results.get("reconstruction")
    if rc:
        for m in ("linear", "predictive"):
            k[f"reconstruction CPU {m} (ns/sample)"] = (rc["cpu"][m], *spread(rc["cpu_runs"][m], "runs", 2))
        r = [p / q for p, q in zip(rc["cpu_runs"]["predictive"], rc["cpu_runs"]["linear"])]
        k["reconstruction CPU predictive/linear"] = (float(np.median(r)), *spread(r, "runs"))
        for c in reconstruction_checks(rc):
            k[f"predictive/linear lag, {c['movement']}"] = (c["lag_ratio"], "deterministic (simulated puck)", None)
    e2e = results.get("e2e")
    if e2e:
        for key in ("loop period", "report to UGen", "force to magnet"):
            v = [r[key]["p99_ms"] for r in e2e["runs"]]
            k[f"realtime {key} p99 (ms)"] = (float(np.median(v)), *spread(v, "runs"))
    sc = results.get("scale")
    if sc:
        for rate, e in sc.items():
            runs = e.get("all_runs", [e["max_without_xrun"]])
            k[f"voices without xruns at {int(rate) // 1000} kHz"] = (
                e["max_without_xrun"], f"{min(runs)}..{max(runs)} over {len(runs)} searches", None)
    return k


def voices(count):
    return "no count" if count < 0 else f"{count} voices"


def repeatability_table(cur):
    lines = ["| number | median in this run | spread in this run |", "| --- | --- | --- |"]
    for label, (v, spread, _) in cur.items():
        lines.append(f"| {label} | {fmt(v, 4)} | {spread} |")
    return "\n".join(lines)
