"""The report-rate part: build/bench/kf_report_rate_bench replays the synthetic hid-recorder
recordings of tests/data/hid (125 Hz 8-bit, 1 kHz 12-bit, 8 kHz 16-bit, made from one known
trajectory by tests/data/hid/make_synthetic.py) through FrictionMouseIn's reconstruction and
compares the position with that trajectory (error, lag, saturated reports and what they lost);
and the simulated puck's mouse at 125 Hz .. 8 kHz the same way. Deterministic: one run."""
import json
import subprocess

from kfharness import paths


def run(bench):
    exe = bench.exe("bench", "kf_report_rate_bench")
    proc = subprocess.run([str(exe), str(paths.test_data_dir() / "hid")], stdout=subprocess.PIPE, text=True,
                          check=True)
    return json.loads(proc.stdout)


def summary_lines(rr):
    lines = []
    for r in rr["recordings"]:
        if r["mode"] != "linear":
            continue
        lines.append(f"report rate {r['rateHz']:5.0f} Hz recording, linear: lag {r['lagMs']:.3f} ms, rms error "
                     f"{r['rmsErrorMm']:.4f} mm ({r['cleanRmsErrorMm']:.4f} mm before saturating), "
                     f"{r['saturatedReports']} of {r['reports']} reports saturated, {r['lostMm']:.2f} mm lost")
    return lines


def recordings_table(rr, table):
    return table(["recording", "T used (ms)", "mode", "lag (ms)", "RMS error (mm)", "at lag (mm)", "max error (mm)",
                  "saturated reports", "lost (mm)", "until the first saturated: lag (ms)", "RMS error (mm)"],
                 [(f"`{r['file']}`", f"{r['intervalMs']:.3f}", r["mode"], f"{r['lagMs']:.3f}",
                   f"{r['rmsErrorMm']:.4f}", f"{r['rmsErrorAtLagMm']:.4f}", f"{r['maxErrorMm']:.4f}",
                   f"{r['saturatedReports']} of {r['reports']}", f"{r['lostMm']:.3f}",
                   f"{r['cleanLagMs']:.3f} (to {r['cleanUntilS']:.3f} s)", f"{r['cleanRmsErrorMm']:.4f}")
                  for r in rr["recordings"]])


def simulated_table(rr, table):
    return table(["movement", "report rate", "T used (ms)", "mode", "lag (ms)", "RMS error (mm)", "at lag (mm)"],
                 [(r["movement"], f"{r['rateHz']:.0f} Hz", f"{r['intervalMs']:.3f}", r["mode"], f"{r['lagMs']:.3f}",
                   f"{r['rmsErrorMm']:.4f}", f"{r['rmsErrorAtLagMm']:.4f}") for r in rr["simulated"]])
