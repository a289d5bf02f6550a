"""The report's figures stage: each condition's Figure 3 (the paper's: 4 s of speed, audio and
force), each participant's coverage maps, the speed distributions friction off against on, and
where each mapping's friction is raised with the speed there. Drawn from the tidy tables
(report_tables) and the statistics (report_statistics); PNG files, named by the caller."""
import numpy as np

from .report_statistics import BIND_MIN_REPORTS, part_of

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIGURE3_S = 4.0


def figure3(condition, m, path, title):
    """4 s of speed, audio and force (the paper's Figure 3), from where the puck most stays in the
    fragment: the 4 s window (in steps of 0.5 s) holding the most recording inside it."""
    t = m["t"]
    if len(t) == 0:
        return None
    starts = np.arange(t[0], max(t[0], t[-1] - FIGURE3_S) + 1e-9, 0.5)
    score = [np.sum(m["inside"][(t >= s) & (t < s + FIGURE3_S)]) for s in starts]
    t0 = starts[int(np.argmax(score))]
    t1 = t0 + FIGURE3_S
    ta, audio = condition.audio()
    tf, force = condition.forces()
    fig, ax = plt.subplots(3, 1, sharex=True, figsize=(9, 6))
    sel = (t >= t0) & (t < t1)
    ax[0].plot(t[sel] - t0, np.abs(m["v"][sel]), lw=0.8)
    ax[0].set_ylabel("speed (mm/s)")
    # The audio as its lowest and highest sample per 2 ms (a pixel is 5 ms): the same picture as
    # every sample drawn, drawn in a fraction of the time.
    sel = (ta >= t0) & (ta < t1)
    piece = max(1, int(round(0.002 / np.median(np.diff(ta[:100]))))) if len(ta) > 1 else 1
    n = np.count_nonzero(sel) // piece * piece
    if n:
        pieces = audio[sel][:n].reshape(-1, piece)
        ax[1].fill_between(ta[sel][:n:piece] - t0, pieces.min(axis=1), pieces.max(axis=1), lw=0.3)
    ax[1].set_ylabel("audio output")
    ax[1].set_ylim(-1.1, 1.1)
    sel = (tf >= t0) & (tf < t1)
    ax[2].plot(tf[sel] - t0, force[sel], lw=0.8)
    ax[2].set_ylabel("friction (N)")
    ax[2].set_ylim(0, max(0.6, 1.1 * force[sel].max() if sel.any() else 0))
    ax[2].set_xlabel(f"time (s) from {t0:.1f} s into the condition")
    sel = (t >= t0) & (t < t1)
    for a in ax:
        a.fill_between(t[sel] - t0, 0, 1, where=m["inside"][sel], transform=a.get_xaxis_transform(),
                       color="0.92", zorder=0)
    fig.suptitle(f"{title} - grey: puck inside the fragment")
    # Fixed margins: the same figure every time, without tight_layout's measuring (a third of the
    # report's time).
    fig.subplots_adjust(left=0.09, right=0.98, bottom=0.09, top=0.93, hspace=0.12)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return t0


def speed_figure(samples, path):
    """Per mapping: the share of the time inside the fragment at each speed, friction off and on."""
    inside = samples[samples.inside.astype(bool)]
    mappings = sorted(samples.mapping.unique())
    fig, axes = plt.subplots(1, len(mappings), figsize=(4.2 * len(mappings), 3.6), squeeze=False)
    bins = np.geomspace(1, 400, 36)
    for ax, mapping in zip(axes[0], mappings):
        for friction, color in ((False, "tab:blue"), (True, "tab:red")):
            chosen = inside[(inside.mapping == mapping) & (inside.friction.astype(bool) == friction)]
            speeds = np.abs(chosen.v_mm_s.to_numpy(float))
            speeds = speeds[speeds > 0]
            if len(speeds):
                # The share of the time in each bin (bins equal on the log axis; a density per mm/s
                # would blow up the narrow slow bins).
                ax.hist(speeds, bins=bins, weights=np.full(len(speeds), 1.0 / len(speeds)), histtype="step",
                        color=color, lw=1.5,
                        label=f"friction {'on' if friction else 'off'} (median {np.median(speeds):.0f} mm/s)")
        ax.set_xscale("log")
        ax.set_title(mapping)
        ax.set_xlabel("speed in the fragment (mm/s)")
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("share of the time in the fragment")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def coverage_figure(session, measured, path):
    n = len(measured)
    fig, axes = plt.subplots(1, n, figsize=(2.3 * n, 2.6), squeeze=False)
    for ax, (condition, m) in zip(axes[0], measured):
        ax.imshow(m["cells"].T, origin="lower", aspect="auto", cmap="Greens", vmin=0, vmax=1.3)
        ax.set_title(f"{condition.position}. {condition.name}\n{100 * m['coverage']:.0f} %", fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    axes[0][0].set_ylabel("speed (slow to fast)", fontsize=8)
    fig.suptitle(f"{session.participant}: coverage (position in the fragment across, speed up)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def binds_figure(samples, parts, path):
    """Per mapping: the mean force commanded along the fragment (friction on, the raised parts
    shaded) over the median speed there with friction off and on (all participants)."""
    mappings = sorted(parts.mapping.unique())
    fig, axes = plt.subplots(2, len(mappings), figsize=(4.2 * len(mappings), 5), sharex="col", squeeze=False)
    for k, mapping in enumerate(mappings):
        mine = parts[parts.mapping == mapping].sort_values("part")
        edges = np.append(mine.from_mm.to_numpy(float), mine.to_mm.max())
        mean, raised = mine.mean_force_n.to_numpy(float), mine.raised.to_numpy(bool)
        mid = (edges[:-1] + edges[1:]) / 2
        force_ax, speed_ax = axes[0][k], axes[1][k]
        force_ax.plot(mid, mean, color="k", lw=0.8)
        for ax in (force_ax, speed_ax):
            ax.fill_between(mid, 0, 1, where=raised, step="mid", transform=ax.get_xaxis_transform(),
                            color="0.9", zorder=0)
        force_ax.set_title(mapping)
        force_ax.set_ylabel("mean force, friction on (N)")
        for friction, color in ((False, "tab:blue"), (True, "tab:red")):
            chosen = samples[(samples.mapping == mapping) & (samples.friction.astype(bool) == friction)]
            if not len(chosen):
                continue
            v = np.abs(chosen.v_mm_s.to_numpy(float))
            part = part_of(chosen.x_mm.to_numpy(float), edges)
            median = [np.median(v[part == i]) if np.count_nonzero(part == i) >= BIND_MIN_REPORTS else np.nan
                      for i in range(len(mid))]
            speed_ax.plot(mid, median, color=color, lw=0.8, label=f"friction {'on' if friction else 'off'}")
        speed_ax.set_yscale("log")
        speed_ax.set_xlabel("position in the fragment (mm)")
        speed_ax.set_ylabel("median speed (mm/s)")
        speed_ax.legend(fontsize=7)
    fig.suptitle("Where the friction is raised (grey), and the speed there", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
