"""The texture_rate part: build/bench/kf_texture_rate_bench (bench/texture_rate_bench.cpp) renders
a sinusoidal grating's force through the framing and the board's firmware at 1 kHz (protocol
2.0, one set-point per 1 ms frame) and 8 kHz (2.1, eight per frame), for periods 0.2 to 5 mm
and speeds 10 to 400 mm/s, against the ideal force. The fidelity figures are deterministic; the
CPU times are medians over rounds, the two rates interleaved in each round, the ratio per round."""
import json
import subprocess

import numpy as np

ROUNDS = 9


def run(bench):
    proc = subprocess.run([str(bench.exe("bench", "kf_texture_rate_bench")), str(ROUNDS)], stdout=subprocess.PIPE,
                          text=True, check=True)
    raw = json.loads(proc.stdout)
    cpu_1k, cpu_8k = np.array(raw["cpuS"][0]), np.array(raw["cpuS"][1])
    ratio = cpu_8k / cpu_1k
    return {"rounds": raw["rounds"], "sample_rate_hz": raw["sampleRateHz"], "block": raw["block"],
            "weber": raw["weber"], "within_weber_hz": raw["withinWeberHz"], "latency_ms": raw["latencyMs"],
            "cpu_ms_per_s": [float(np.median(cpu_1k)) * 1e3, float(np.median(cpu_8k)) * 1e3],
            "cpu_ratio": float(np.median(ratio)), "cpu_ratio_range": [float(ratio.min()), float(ratio.max())],
            "cases": raw["cases"]}


def summary_lines(tr):
    return [f"texture_rate: a grating's line within one Weber fraction ({tr['weber']:g}) up to "
            f"{tr['within_weber_hz'][0]:.0f} Hz at 1 kHz force, {tr['within_weber_hz'][1]:.0f} Hz at 8 kHz; "
            f"step latency {tr['latency_ms'][0]:.2f} / {tr['latency_ms'][1]:.2f} ms; CPU "
            f"{tr['cpu_ms_per_s'][0]:.2f} / {tr['cpu_ms_per_s'][1]:.2f} ms per s of force ({tr['cpu_ratio']:.2f}x)"]


def fidelity_table(tr, table):
    def cell(c, r):
        return f"{c['gainDb'][r]:+.2f} dB, {c['weber'][r]:.2f} W, {c['spurDb'][r]:.0f} dB"
    rows = sorted(tr["cases"], key=lambda c: (c["frequencyHz"], c["periodMm"]))
    return table(["period (mm)", "speed (mm/s)", "frequency (Hz)", "1 kHz: gain, Weber, largest other line",
                  "8 kHz: gain, Weber, largest other line"],
                 [(f"{c['periodMm']:g}", f"{c['speedMmPerS']:g}", f"{c['frequencyHz']:g}", cell(c, 0), cell(c, 1))
                  for c in rows])
