"""The texture_rate part: build/bench/kf_texture_rate_bench (bench/texture_rate_bench.cpp) renders
a sinusoidal grating's force through the framing and the board's firmware at 1 kHz (protocol
2.0, one set-point per 1 ms frame) and 8 kHz (2.1, eight per frame), each frame its samples' mean,
and at 8 kHz through the anti-alias filter too, for periods 0.2 to 5 mm and speeds 10 to 400 mm/s,
against the ideal force. The fidelity figures are deterministic; the CPU times are medians over
rounds, the variants interleaved in each round, the ratios to 1 kHz's per round."""
import json
import subprocess

import numpy as np

ROUNDS = 9


def run(bench):
    proc = subprocess.run([str(bench.exe("bench", "kf_texture_rate_bench")), str(ROUNDS)], stdout=subprocess.PIPE,
                          text=True, check=True)
    raw = json.loads(proc.stdout)
    cpu = [np.array(rounds) for rounds in raw["cpuS"]]
    ratios = [c / cpu[0] for c in cpu]  # to 1 kHz's, round by round
    return {"rounds": raw["rounds"], "sample_rate_hz": raw["sampleRateHz"], "block": raw["block"],
            "weber": raw["weber"], "variants": [v["name"] for v in raw["variants"]],
            "within_weber_hz": raw["withinWeberHz"], "latency_ms": raw["latencyMs"],
            "cpu_ms_per_s": [float(np.median(c)) * 1e3 for c in cpu],
            "cpu_ratio": [float(np.median(r)) for r in ratios],
            "cpu_ratio_range": [[float(r.min()), float(r.max())] for r in ratios], "cases": raw["cases"]}


def summary_lines(tr):
    per = [f"{name}: up to {hz:.0f} Hz, step latency {ms:.2f} ms, CPU {cpu:.2f} ms per s of force ({ratio:.2f}x)"
           for name, hz, ms, cpu, ratio in zip(tr["variants"], tr["within_weber_hz"], tr["latency_ms"],
                                               tr["cpu_ms_per_s"], tr["cpu_ratio"])]
    return [f"texture_rate: a grating's line within one Weber fraction ({tr['weber']:g}): " + "; ".join(per)]


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
