"""The PNGs of the report, one function per plot."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .common import FORCE_FRAME_MS, GRID_SPEEDS, MAPPINGS, SR  # noqa: E402
from .goals import FORCE_GOAL_MS, JITTER_GOAL_MS  # noqa: E402
from .timing import PHASES, READERS  # noqa: E402


def _save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_timing(res, path):
    names = [n for n in PHASES if n != "empty"]
    fig, ax = plt.subplots(figsize=(9, 4))
    for i, n in enumerate(names):
        v = res["ns"]["cpu"][n]
        ax.scatter([i] * len(v), v, s=14, color="C0")
        ax.scatter([i], [np.median(v)], marker="_", s=300, color="C3")
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names, rotation=30)
    ax.set_ylabel("CPU ns per instance per sample\n(minus the empty phase)")
    ax.set_title(f"scsynth NRT, {res['instances']} instances per phase, {res['rounds']} rounds (red: median)")
    ax.grid(alpha=0.3)
    _save(fig, path)


def plot_spatial(sp, path):
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, (label, entry) in zip(axes, sp["index"].items()):
        for ugen, color in (("BufRd", "C3"), ("SpatialBufRd", "C0")):
            t, d = entry["_traces"][ugen]
            ax.plot(t / SR, d, ".", ms=1, color=color, label=f"{ugen} cubic")
        ax.set_title(label, fontsize=9)
        ax.set_xlabel("s")
        ax.set_ylabel("effective index - exact index (samples)")
        ax.legend(markerscale=8, fontsize=8)
        ax.grid(alpha=0.3)
    _save(fig, path)


def plot_loudness(data, want, path):
    t = np.arange(len(want)) / SR
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    axes[0].plot(t, want, color="k", lw=1, label="equations (1), (2) in double")
    axes[0].plot(t, data[:, 3], color="C2", lw=0.5, alpha=0.6, label="Amplitude chain")
    axes[0].set_ylabel("force (N)")
    axes[0].legend(fontsize=8)
    for name, col, color in (("LoudnessToFriction", 1, "C0"), ("RunningSum chain", 2, "C3")):
        axes[1].semilogy(t, np.abs(data[:, col] - want) + 1e-12, ".", ms=1, color=color, label=name)
    axes[1].axhline(1e-6, color="k", ls="--", lw=0.8)
    axes[1].set_ylabel("|error| (N), 1e-12 added")
    axes[1].set_xlabel("s")
    axes[1].legend(markerscale=8, fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    _save(fig, path)


def plot_log_choice(lc, path):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, r in enumerate(lc["rows"]):
        if "worst_n" not in r:
            continue
        ax.scatter(r["core_ns"], r["worst_n"], color=f"C{i % 10}", label=r["name"])
    ax.set_yscale("log")
    ax.axhline(1e-6, color="k", ls="--", lw=0.8)
    ax.set_xlabel("core loop ns per sample (every sample inside the clip range)")
    ax.set_ylabel("worst force error (N) over the clip range")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    _save(fig, path)

def plot_spatial_tradeoff(tm, sp, path):
    """CPU against error: each reader's CPU ratio to BufRd cubic (median over rounds, bars: min..max)
    against its max error vs the continuous signal, one point per mapping and speed."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    markers = {MAPPINGS[0]: "o", MAPPINGS[1]: "s", MAPPINGS[2]: "^"}
    for ax, stat in zip(axes, ("max_vs_signal", "rms_vs_signal")):
        for j, (name, label) in enumerate(READERS):
            r = tm["vs_bufrd4"][name]["cpu-empty"]
            color = f"C{j}"
            for entry in sp["pilot"].values():
                e = entry[label][stat]
                jitter = 1 + 0.012 * (GRID_SPEEDS.index(entry["speed"]) - 1.5)
                ax.errorbar(r["median"] * jitter, max(e, 1e-9), xerr=[[r["median"] - r["min"]], [r["max"] - r["median"]]],
                            fmt=markers[entry["spm"]], color=color, ms=5, elinewidth=0.6, alpha=0.8,
                            label=label if entry is next(iter(sp["pilot"].values())) else None)
        ax.set_yscale("log")
        ax.set_xlabel("CPU per sample / BufRd cubic (median over rounds, min..max)")
        ax.set_title(("max" if stat.startswith("max") else "rms") + " |error| vs the continuous sine", fontsize=10)
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("|error| (full scale 1)")
    axes[0].legend(fontsize=7, loc="lower left")
    axes[1].text(0.02, 0.02, f"o {MAPPINGS[0]}, s {MAPPINGS[1]}, ^ {MAPPINGS[2]} samples/mm;\n"
                 f"speeds {', '.join(str(v) for v in GRID_SPEEDS)} mm/s left to right",
                 transform=axes[1].transAxes, fontsize=7)
    _save(fig, path)


def plot_reconstruction(rc, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    movements = list(dict.fromkeys(r["movement"] for r in rc["accuracy"]))
    modes = ["hold", "linear", "predictive"]
    w = 0.27
    for k, mode in enumerate(modes):
        rows = {r["movement"]: r for r in rc["accuracy"] if r["mode"] == mode}
        x = np.arange(len(movements)) + (k - 1) * w
        axes[0].bar(x, [rows[m]["lagMs"] for m in movements], w, color=f"C{k}", label=mode)
        axes[1].bar(x, [rows[m]["rmsErrorMm"] for m in movements], w, color=f"C{k}",
                    label=f"{mode} ({rc['cpu'][mode]:.1f} ns/sample)")
    for ax, ylabel in zip(axes, ("lag (ms)", "RMS position error (mm)")):
        ax.set_xticks(range(len(movements)))
        ax.set_xticklabels(movements, fontsize=8)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, axis="y")
    axes[1].set_yscale("log")
    axes[0].legend(fontsize=8)
    axes[1].legend(fontsize=8)
    fig.suptitle("FrictionMouseIn reconstruction against the simulated puck's true trajectory", fontsize=10)
    _save(fig, path)


def plot_e2e(e2e, path):
    what = [("loop period", "1 kHz loop period"), ("report to UGen", "report -> UGen"),
            ("force to magnet", "force -> magnet")]
    fig, ax = plt.subplots(figsize=(9, 4))
    for i, (key, label) in enumerate(what):
        for j, run in enumerate(e2e["runs"]):
            x = i + (j - (len(e2e["runs"]) - 1) / 2) * 0.2
            v = run[key]
            ax.plot([x, x], [v["p50_ms"], v["max_ms"]], color="0.6", lw=1)
            ax.plot(x, v["p50_ms"], "o", color="C0", label="p50" if i == j == 0 else None)
            ax.plot(x, v["p99_ms"], "s", color="C3", label="p99" if i == j == 0 else None)
            ax.plot(x, v["max_ms"], "v", color="k", label="max" if i == j == 0 else None)
    ax.axhline(FORCE_GOAL_MS, color="C3", ls="--", lw=0.8, label="force goal: one frame + one block")
    ax.axhline(FORCE_FRAME_MS + JITTER_GOAL_MS, color="C2", ls=":", lw=0.8,
               label=f"loop goal: one frame + {JITTER_GOAL_MS * 1e3:.0f} us (p99)")
    ax.set_xticks(range(len(what)))
    ax.set_xticklabels([w[1] for w in what])
    ax.set_yscale("log")
    ax.set_ylabel("ms")
    ax.set_title(f"realtime, jackd dummy {SR // 1000} kHz / 64, FrictionPilot on FrictionDevice.sim, {len(e2e['runs'])} runs", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    _save(fig, path)


def plot_scale(scale, path):
    fig, axes = plt.subplots(1, len(scale), figsize=(5.5 * len(scale), 4), squeeze=False)
    for ax, (rate, sc) in zip(axes[0], scale.items()):
        st = sorted(sc["steps"], key=lambda r: r["voices"])
        v = [r["voices"] for r in st]
        ax.plot(v, [r["avg_cpu"] for r in st], "o-", color="C0", label="scsynth avg CPU %")
        ax.plot(v, [r["peak_cpu"] for r in st], "s", color="C1", ms=4, label="scsynth peak CPU %")
        ax2 = ax.twinx()
        ax2.bar(v, [max(max(r["window_xruns"]), 0.5) for r in st], width=max(max(v), 1) * 0.015, color="C3",
                alpha=0.5, label="xruns in the worst window")
        ax2.axhline(sc["xrun_limit"], color="C3", ls="--", lw=0.8)
        ax2.set_yscale("log")
        ax2.set_ylabel("JACK: scsynth not finished (per window)", color="C3", fontsize=8)
        ax.axvline(max(sc["max_without_xrun"], 0), color="k", ls=":", lw=0.8)
        ax.set_xlabel("voices")
        ax.set_ylabel("%")
        ax.set_title(f"{int(rate) // 1000} kHz, the median search: {sc['max_without_xrun']} voices without an xrun",
                     fontsize=10)
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(alpha=0.3)
    _save(fig, path)

