"""The patterns part: build/bench/kf_patterns_bench (bench/patterns_bench.cpp) runs every
FrictionPattern kind over a fine pattern (0.2 mm; bumps2D and texture2D along 30 degrees) at 5 and 300 mm/s,
with anti-aliasing on and off interleaved in every round (fresh cores on the same path, CPU time
of the thread), and LoudnessToFriction on noise in the same rounds; and the largest alias in the
1 ms frames at 300 mm/s, on and off, measured as the dsp tests measure it. The alias figures are
deterministic; the times are medians over rounds, with ratios taken per round."""
import json
import subprocess

import numpy as np

ROUNDS = 15


def run(bench):
    proc = subprocess.run([str(bench.exe("bench", "kf_patterns_bench")), str(ROUNDS)], stdout=subprocess.PIPE,
                          text=True, check=True)
    raw = json.loads(proc.stdout)
    loudness = np.array(raw["loudnessNs"])
    cases = []
    for c in raw["cases"]:
        on, off = np.array(c["nsOn"]), np.array(c["nsOff"])
        ratio, vs_loudness = on / off, on / loudness
        case = {"kind": c["kind"], "speed_mm_per_s": c["speedMmPerS"], "p": c["p"],
                "ns_on": float(np.median(on)), "ns_off": float(np.median(off)),
                "on_over_off": float(np.median(ratio)), "on_over_off_range": [float(ratio.min()), float(ratio.max())],
                "on_over_loudness": float(np.median(vs_loudness))}
        if "aliasOnN" in c:
            case.update(alias_on_n=c["aliasOnN"], alias_off_n=c["aliasOffN"])
        cases.append(case)
    return {"rounds": raw["rounds"], "seconds": raw["seconds"], "sample_rate_hz": raw["sampleRateHz"],
            "block": raw["block"], "fine_mm": raw["fineMm"], "angle_deg": raw["angleDeg"],
            "loudness_ns": float(np.median(loudness)), "cases": cases}


def summary_lines(pt):
    lines = [f"patterns: ns/sample with anti-aliasing on / off (median of {pt['rounds']} rounds), over a "
             f"{pt['fine_mm']:g} mm pattern; LoudnessToFriction {pt['loudness_ns']:.2f} ns/sample"]
    for c in pt["cases"]:
        alias = (f"; alias at 300 mm/s on {c['alias_on_n']:.3g} N, off {c['alias_off_n']:.3g} N"
                 if "alias_on_n" in c else "")
        lines.append(f"  {c['kind']:9s} {c['speed_mm_per_s']:5g} mm/s: {c['ns_on']:7.1f} / {c['ns_off']:6.1f} ns "
                     f"= {c['on_over_off']:.2f}x, {c['on_over_loudness']:.0f}x LoudnessToFriction{alias}")
    return lines


def cost_table(pt, table):
    return table(["kind", "speed (mm/s)", "ns/sample on", "off", "on / off", "[min..max] over rounds",
                  "on / LoudnessToFriction"],
                 [(c["kind"], f"{c['speed_mm_per_s']:g}", f"{c['ns_on']:.1f}", f"{c['ns_off']:.1f}",
                   f"{c['on_over_off']:.2f}", f"{c['on_over_off_range'][0]:.2f}..{c['on_over_off_range'][1]:.2f}",
                   f"{c['on_over_loudness']:.1f}") for c in pt["cases"]])


def alias_table(pt, table):
    return table(["kind", "parameters (p1, p2, p3)", "largest alias, anti-aliasing on (N)", "off (N)"],
                 [(c["kind"], ", ".join(f"{p:g}" for p in c["p"]), f"{c['alias_on_n']:.3g}", f"{c['alias_off_n']:.3g}")
                  for c in pt["cases"] if "alias_on_n" in c])
