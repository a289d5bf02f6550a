"""The texture_rate part: build/bench/kf_texture_rate_bench (bench/texture_rate_bench.cpp) renders
a sinusoidal grating's force through the framing and the board's firmware at 1 kHz (protocol
2.0, one set-point per 1 ms frame) and 8 kHz (2.1, eight per frame), each frame its samples' mean,
and at 8 kHz through the anti-alias filter too, for periods 0.2 to 5 mm and speeds 10 to 400 mm/s,
against the ideal force; and textures (FrictionPattern.texture, three bands of periods) at the same
speeds, against the ideal through their spectra. The fidelity figures are deterministic; the CPU
times are medians over rounds, the variants interleaved in each round, the ratios to 1 kHz's per
round."""
import json
import subprocess

import numpy as np

ROUNDS = 9
DEVICE_ROUNDS, DEVICE_SECONDS = 5, 2.0  # build/bench/kf_device_rate_bench: the device's threads at each rate


def run(bench):
    proc = subprocess.run([str(bench.exe("bench", "kf_texture_rate_bench")), str(ROUNDS)], stdout=subprocess.PIPE,
                          text=True, check=True)
    raw = json.loads(proc.stdout)
    device = json.loads(subprocess.run([str(bench.exe("bench", "kf_device_rate_bench")), str(DEVICE_ROUNDS),
                                        str(DEVICE_SECONDS)], stdout=subprocess.PIPE, text=True, check=True).stdout)
    cpu = [np.array(rounds) for rounds in raw["cpuS"]]
    ratios = [c / cpu[0] for c in cpu]  # to 1 kHz's, round by round
    return {"rounds": raw["rounds"], "sample_rate_hz": raw["sampleRateHz"], "block": raw["block"],
            "weber": raw["weber"], "variants": [v["name"] for v in raw["variants"]],
            "within_weber_hz": raw["withinWeberHz"], "latency_ms": raw["latencyMs"],
            "cpu_ms_per_s": [float(np.median(c)) * 1e3 for c in cpu],
            "cpu_ratio": [float(np.median(r)) for r in ratios],
            "cpu_ratio_range": [[float(r.min()), float(r.max())] for r in ratios], "cases": raw["cases"],
            "textures": raw["textures"], "device": device_rates(device)}


def device_rates(raw):
    """Per rate: the host threads' CPU (ms per s) as a median over rounds, its range, the ratio to
    1 kHz's round by round, and the set-points a second the board was sent."""
    cpu = [np.array(r["cpuSPerS"]) for r in raw["rates"]]
    return {"seconds": raw["seconds"], "rounds": raw["rounds"],
            "rates": [{"rate_hz": r["rateHz"], "cpu_ms_per_s": float(np.median(c)) * 1e3,
                       "cpu_range_ms": [float(c.min()) * 1e3, float(c.max()) * 1e3],
                       "ratio": float(np.median(c / cpu[0])), "set_points_per_s": float(np.median(r["setPointsPerS"]))}
                      for r, c in zip(raw["rates"], cpu)]}


def device_table(tr, table):
    return table(["force", "device's threads' CPU (ms per s)", "range over rounds", "/ 1 kHz's", "set-points sent per s"],
                 [(f"{r['rate_hz'] / 1000:g} kHz", f"{r['cpu_ms_per_s']:.2f}",
                   f"{r['cpu_range_ms'][0]:.2f}..{r['cpu_range_ms'][1]:.2f}", f"{r['ratio']:.2f}x",
                   f"{r['set_points_per_s']:.0f}") for r in tr["device"]["rates"]])


def textures_within_weber_hz(tr):
    """Per variant: the highest top frequency (Hz: the band's highest spatial frequency times the
    speed) of a texture whose every third-octave stays within one Weber fraction."""
    return [max([t["hiPerMm"] * t["speedMmPerS"] for t in tr["textures"] if t["worstWeber"][r] <= 1], default=0.0)
            for r in range(len(tr["variants"]))]


def summary_lines(tr):
    per = [f"{name}: up to {hz:.0f} Hz, step latency {ms:.2f} ms, CPU {cpu:.2f} ms per s of force ({ratio:.2f}x)"
           for name, hz, ms, cpu, ratio in zip(tr["variants"], tr["within_weber_hz"], tr["latency_ms"],
                                               tr["cpu_ms_per_s"], tr["cpu_ratio"])]
    textures = "; ".join(f"{name}: {hz:.0f} Hz" for name, hz in zip(tr["variants"], textures_within_weber_hz(tr)))
    device = "; ".join(f"{r['rate_hz'] / 1000:g} kHz: {r['cpu_ms_per_s']:.1f} ms per s" for r in tr["device"]["rates"])
    return [f"texture_rate: a grating's line within one Weber fraction ({tr['weber']:g}): " + "; ".join(per),
            f"texture_rate: the highest texture (its top frequency) within one Weber fraction in every third-octave: "
            f"{textures}",
            f"texture_rate: the device's threads' CPU: {device}"]


def variants_table(tr, table):
    return table(["force", "a line within one Weber fraction up to (Hz)", "step latency (ms)",
                  "CPU (ms per s of force)", "CPU / 1 kHz's (over rounds)"],
                 [(name, f"{hz:.0f}", f"{ms:.2f}", f"{cpu:.2f}", f"{ratio:.2f}x ({lo:.2f}..{hi:.2f})")
                  for name, hz, ms, cpu, ratio, (lo, hi) in zip(tr["variants"], tr["within_weber_hz"], tr["latency_ms"],
                                                                tr["cpu_ms_per_s"], tr["cpu_ratio"],
                                                                tr["cpu_ratio_range"])])


def fidelity_table(tr, table):
    def cell(c, r):
        return f"{c['gainDb'][r]:+.2f} dB, {c['weber'][r]:.2f} W, {c['spurDb'][r]:.0f} dB"
    rows = sorted(tr["cases"], key=lambda c: (c["frequencyHz"], c["periodMm"]))
    return table(["period (mm)", "speed (mm/s)", "frequency (Hz)"]
                 + [f"{name}: gain, Weber, largest other line" for name in tr["variants"]],
                 [(f"{c['periodMm']:g}", f"{c['speedMmPerS']:g}", f"{c['frequencyHz']:g}",
                   *(cell(c, r) for r in range(len(tr["variants"])))) for c in rows])


def textures_table(tr, table):
    def cell(t, r):
        return f"{t['bandWeber'][r]:.2f} W, {t['worstWeber'][r]:.2f} W at {t['worstHz'][r]:.0f} Hz, {t['spurDb'][r]:.0f} dB"
    rows = sorted(tr["textures"], key=lambda t: (t["hiPerMm"] * t["speedMmPerS"], t["loPerMm"]))
    return table(["periods (mm)", "speed (mm/s)", "frequencies (Hz)"]
                 + [f"{name}: band, worst third-octave, outside the band" for name in tr["variants"]],
                 [(f"{1 / t['hiPerMm']:g}-{1 / t['loPerMm']:g}", f"{t['speedMmPerS']:g}",
                   f"{t['loPerMm'] * t['speedMmPerS']:g}-{t['hiPerMm'] * t['speedMmPerS']:g}",
                   *(cell(t, r) for r in range(len(tr["variants"])))) for t in rows])
