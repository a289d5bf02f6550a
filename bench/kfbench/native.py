"""The C++ benchmarks built in build/bench: the logarithm of equation (2) (kf_log_choice) and
FrictionMouseIn's reconstruction modes against the simulated puck (kf_reconstruction_bench)."""
import json
import os
import re
import subprocess

import numpy as np

LAG_GOAL = 0.5  # predictive lag at most this share of linear's (the paper's mode)


def core_path(bench):
    """The cores' code path in this environment (KF_CORE_PATH) on this processor, as kf_core_path
    reports it: {"path": "avx2" or "portable", "avx2_fma": bool, "requested": KF_CORE_PATH or None}."""
    out = subprocess.run([str(bench.exe("bench", "kf_core_path"))], stdout=subprocess.PIPE, text=True,
                         check=True).stdout
    fields = dict(line.split(" ", 1) for line in out.splitlines() if " " in line)
    return {"path": fields.get("path", "?"), "avx2_fma": fields.get("avx2_fma") == "yes",
            "requested": os.environ.get("KF_CORE_PATH")}


def run_log_choice(bench):
    proc = subprocess.run([str(bench.exe("bench", "kf_log_choice"))], stdout=subprocess.PIPE, text=True, check=True)
    rows = []
    for line in proc.stdout.splitlines():
        m = re.match(r'RESULT name="([^"]*)"(.*)', line)
        if m:
            row = {"name": m.group(1)}
            for k, v in re.findall(r"(\w+)=([-+0-9.eE]+)", m.group(2)):
                row[k] = float(v)
            rows.append(row)
    return {"rows": rows, "stdout": proc.stdout}


def run_reconstruction(bench, runs=3):
    """kf_reconstruction_bench `runs` times: accuracy is deterministic (the simulated puck), the
    CPU per sample is the median of each run's five interleaved rounds; the spread is over runs."""
    outs = []
    for _ in range(runs):
        proc = subprocess.run([str(bench.exe("bench", "kf_reconstruction_bench"))], stdout=subprocess.PIPE, text=True,
                              check=True)
        outs.append(json.loads(proc.stdout))
    res = {"accuracy": outs[0]["accuracy"], "runs": runs,
           "cpu_runs": {mode: [o["cpuNsPerSample"][mode] for o in outs] for mode in outs[0]["cpuNsPerSample"]},
           "deterministic": all(o["accuracy"] == outs[0]["accuracy"] for o in outs)}
    res["cpu"] = {mode: float(np.median(v)) for mode, v in res["cpu_runs"].items()}
    return res


def reconstruction_checks(rc):
    """Per movement: predictive |lag| <= LAG_GOAL x linear's at no more than linear's RMS error."""
    rows = {}
    for r in rc["accuracy"]:
        rows.setdefault(r["movement"], {})[r["mode"]] = r
    checks = []
    for movement, m in rows.items():
        p, lin = m["predictive"], m["linear"]
        # A predictor that leads (negative lag) is as far off in time as one that lags.
        lag_ratio = abs(p["lagMs"]) / lin["lagMs"] if lin["lagMs"] > 0 else float("inf")
        checks.append({"movement": movement, "lag_ratio": lag_ratio, "pred_lag_ms": p["lagMs"],
                       "lin_lag_ms": lin["lagMs"], "pred_rms_mm": p["rmsErrorMm"], "lin_rms_mm": lin["rmsErrorMm"],
                       "met": lag_ratio <= LAG_GOAL and p["rmsErrorMm"] <= lin["rmsErrorMm"]})
    return checks
