"""The thresholds part: every threshold procedure (sclang, no server) run RUNS times against the
model observer of kfharness.thresholds, in one sclang; per procedure and number of trials the
bias and spread of its estimate, beside the established implementations given the same observer
and the same answers:
  - QUEST+: Debian's python3-questplus given our runs' answers (the level it would choose before
    each trial, its estimate after them) and run on its own RUNS times against the same observer
    (numpy's random numbers);
  - the fits: each run's trials fitted by kfstudy.psychometric and by Debian's psignifit;
  - the staircases: Levitt's convergence points (70.7 %, 79.4 %) of the observer's function;
  - the theory's spread: the Cramer-Rao bound of log10 threshold (Fisher information of the
    Weibull's three free parameters at the observer's values, for the levels a run used).
Bias is the mean of log10(estimate / target), spread the sd of log10(estimate) over runs."""
import os
import time

import numpy as np

from kfharness import psignifit_cli, questplus_ref, thresholds
from kfstudy import psychometric

from .common import log

RUNS = 200
OBS = thresholds.OBSERVER


def _targets():
    args = (OBS["threshold"], OBS["slope"], OBS["guess"], OBS["lapse"])
    return {"threshold": OBS["threshold"], "level_707": psychometric.level_at(0.5 ** 0.5, *args),
            "level_794": psychometric.level_at(0.5 ** (1 / 3), *args)}


TARGET_OF = {"questplus": "threshold", "constant": "threshold", "staircase 1-up-2-down": "level_707",
             "staircase 1-up-3-down": "level_794"}


def _stats(estimates, target):
    logs = np.log10(np.asarray(estimates, dtype=float))
    return {"n": int(len(logs)), "bias_log10": float(np.mean(logs) - np.log10(target)),
            "sd_log10": float(np.std(logs, ddof=1)), "median": float(10 ** np.median(logs)),
            "rms_log10": float(np.sqrt(np.mean((logs - np.log10(target)) ** 2)))}


def cramer_rao_sd_log10(levels):
    """The theory's smallest sd of an unbiased log10 threshold from trials at these levels, at the
    observer's values (kfstudy.psychometric)."""
    return psychometric.cramer_rao_sd_log10(levels, OBS["threshold"], OBS["slope"], OBS["guess"], OBS["lapse"])


def run(bench, runs=RUNS):
    load_before = os.getloadavg()
    t0 = time.monotonic()
    records = thresholds.simulate({name: runs for name in thresholds.PROCEDURES}, bench.work / "thresholds.jsonl",
                                  include_paths=bench.include_paths)
    sclang_s = time.monotonic() - t0
    log(f"thresholds: {len(records)} simulated runs in sclang took {sclang_s:.1f} s")
    targets = _targets()
    out = {"runs": runs, "observer": OBS, "targets": targets, "sclang_s": sclang_s, "procedures": {}}
    for name, (_, checkpoints) in thresholds.PROCEDURES.items():
        mine = [r for r in records if r["procedure"] == name]
        target = targets[TARGET_OF[name]]
        entry = {"target": TARGET_OF[name], "target_level": target, "checkpoints": checkpoints,
                 "ours": {str(n): _stats([r["estimates"][str(n)]["threshold"] for r in mine], target)
                          for n in checkpoints},
                 "trials_per_run": float(np.mean([len(r["levels"]) for r in mine]))}
        if name.startswith("staircase"):  # the same estimates against the observer's threshold
            entry["ours_vs_threshold"] = _stats([r["estimates"][str(checkpoints[-1])]["threshold"] for r in mine],
                                                OBS["threshold"])
        entry["cramer_rao_sd_log10"] = float(np.median([cramer_rao_sd_log10(r["levels"]) for r in mine]))
        t1 = time.monotonic()
        fits = [(psychometric.fit(r["levels"], r["correct"]), psignifit_cli.fit(r["levels"], r["correct"]))
                for r in mine]
        entry["fit"] = {"ours": _stats([f[0]["threshold"] for f in fits], OBS["threshold"]),
                        "psignifit": _stats([f[1]["threshold"] for f in fits], OBS["threshold"]),
                        "median_abs_difference_log10": float(np.median(
                            [abs(np.log10(a["threshold"] / b["threshold"])) for a, b in fits])),
                        "seconds": time.monotonic() - t1}
        log(f"thresholds: {name}: fits of {len(fits)} runs by ours and psignifit")
        out["procedures"][name] = entry
    out["questplus_reference"] = questplus_reference(records, runs)
    out["load_before"], out["load_after"] = list(load_before), list(os.getloadavg())
    return out


def questplus_reference(records, runs):
    levels = questplus_ref.log_levels(0.1, 10, 30)
    checkpoints = thresholds.PROCEDURES["questplus"][1]
    quest = [r for r in records if r["procedure"] == "questplus"]
    t0 = time.monotonic()
    same_choice = same_trials = 0
    differences = []
    for r in quest:
        chosen, estimate = questplus_ref.replay(levels, r["levels"], r["correct"])
        same_choice += sum(abs(a - b) <= 1e-9 * b for a, b in zip(chosen, r["levels"]))
        same_trials += len(chosen)
        differences.append(abs(estimate["threshold"] / r["estimates"][str(checkpoints[-1])]["threshold"] - 1))
    replay_s = time.monotonic() - t0
    log(f"thresholds: python3-questplus replayed {len(quest)} runs ({replay_s:.0f} s)")
    t0 = time.monotonic()
    own = [questplus_ref.simulate(levels, OBS, checkpoints[-1], checkpoints, seed=5000 + i) for i in range(runs)]
    own_s = time.monotonic() - t0
    log(f"thresholds: python3-questplus ran {runs} runs of its own ({own_s:.0f} s)")
    return {"same_choice": same_choice, "trials": same_trials, "max_relative_difference": float(max(differences)),
            "replay_s": replay_s, "own_s": own_s,
            "own": {str(n): _stats([e[n]["threshold"] for e in own], OBS["threshold"]) for n in checkpoints}}


def summary_lines(th):
    lines = [f"thresholds: {th['runs']} simulated runs per procedure against a Weibull observer (threshold "
             f"{OBS['threshold']:g}, slope {OBS['slope']:g}, lapse {OBS['lapse']:g}); bias and sd of log10 estimates"]
    for name, e in th["procedures"].items():
        cells = ", ".join(f"{n} trials {s['bias_log10']:+.3f} / {s['sd_log10']:.3f}" for n, s in e["ours"].items())
        lines.append(f"  {name:22s} vs {e['target']}: {cells}; Cramer-Rao sd {e['cramer_rao_sd_log10']:.3f}")
    q = th["questplus_reference"]
    lines.append(f"  python3-questplus given the same answers chose the same level in {q['same_choice']} of "
                 f"{q['trials']} trials; its own runs: " + ", ".join(
                     f"{n} trials {s['bias_log10']:+.3f} / {s['sd_log10']:.3f}" for n, s in q["own"].items()))
    return lines


def tables(th, table):
    rows = []
    for name, e in th["procedures"].items():
        for n, s in e["ours"].items():
            rows.append((name, e["target"], f"{e['target_level']:.4f}", n, f"{s['bias_log10']:+.4f}",
                         f"{s['sd_log10']:.4f}", f"{s['rms_log10']:.4f}", f"{s['median']:.4f}"))
        if name == "questplus":
            for n, s in th["questplus_reference"]["own"].items():
                rows.append(("python3-questplus (its own runs)", "threshold", f"{OBS['threshold']:.4f}", n,
                             f"{s['bias_log10']:+.4f}", f"{s['sd_log10']:.4f}", f"{s['rms_log10']:.4f}",
                             f"{s['median']:.4f}"))
    procedures = table(["procedure", "target", "target level", "trials", "bias (log10)", "sd (log10)",
                        "rms error (log10)", "median estimate"], rows)
    fit_rows = [(name, f"{e['trials_per_run']:.0f}", f"{e['fit']['ours']['bias_log10']:+.4f}",
                 f"{e['fit']['ours']['sd_log10']:.4f}", f"{e['fit']['psignifit']['bias_log10']:+.4f}",
                 f"{e['fit']['psignifit']['sd_log10']:.4f}", f"{e['fit']['median_abs_difference_log10']:.2e}",
                 f"{e['cramer_rao_sd_log10']:.4f}")
                for name, e in th["procedures"].items()]
    fits = table(["trials of", "trials per run", "our fit: bias (log10)", "sd", "psignifit: bias (log10)", "sd",
                  "median abs. log10(ours / psignifit)", "Cramer-Rao sd (log10)"], fit_rows)
    return procedures, fits


def plot(th, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for i, (name, e) in enumerate(th["procedures"].items()):
        n = [int(k) for k in e["ours"]]
        for ax, key in zip(axes, ("bias_log10", "sd_log10")):
            ax.plot(n, [s[key] for s in e["ours"].values()], "o-", color=f"C{i}", label=f"{name} (vs {e['target']})")
    q = th["questplus_reference"]["own"]
    for ax, key in zip(axes, ("bias_log10", "sd_log10")):
        ax.plot([int(k) for k in q], [s[key] for s in q.values()], "s--", color="C3", mfc="none",
                label="python3-questplus, own runs")
        ax.set_xscale("log")
        ax.set_xlabel("trials")
        ax.grid(alpha=0.3, which="both")
    axes[0].axhline(0, color="0.5", lw=0.8)
    axes[0].set_ylabel("bias: mean log10(estimate / target)")
    axes[1].set_ylabel("spread: sd of log10 estimate")
    axes[1].legend(fontsize=7)
    fig.suptitle(f"threshold procedures, {th['runs']} runs each, Weibull observer", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
