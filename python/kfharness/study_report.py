"""The report of a FrictionStudy's sessions (python/kfharness/study_session.py reads them): per
participant and over all, the conditions in the order run, their durations, the coverage reached,
the speed distributions per condition (friction off against on), the answers, each condition's
Figure 3 (4 s of speed, audio and force), the "binds" statistic (the paper's observation that
raised friction binds movement: the speed in the fragment with friction off minus on, per
participant and mapping, and a paired t test over participants), and the threshold fits of any
threshold conditions (kfharness.psychometric). Markdown with PNG figures and CSV files beside it.
"""
import csv
from pathlib import Path

import numpy as np

from . import study_session

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIGURE3_S = 4.0


def _measure(session, condition):
    t, x, v = condition.track()
    inside = (x >= condition.area_mm[0]) & (x < condition.area_mm[1])
    cells = study_session.coverage(x, v, condition.area_mm, session.coverage_settings)
    period = np.median(np.diff(t)) if len(t) > 1 else 0.0
    return dict(t=t, x=x, v=v, inside=inside, cells=cells,
                coverage=float(cells.mean()) if cells.size else 0.0,
                speeds_inside=np.abs(v[inside]), time_inside_s=float(inside.sum() * period))


def _figure3(condition, m, path, title):
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
    sel = (ta >= t0) & (ta < t1)
    ax[1].plot(ta[sel] - t0, audio[sel], lw=0.3)
    ax[1].set_ylabel("audio output")
    ax[1].set_ylim(-1.1, 1.1)
    sel = (tf >= t0) & (tf < t1)
    ax[2].plot(tf[sel] - t0, force[sel], lw=0.8)
    ax[2].set_ylabel("friction (N)")
    ax[2].set_ylim(0, 0.6)
    ax[2].set_xlabel(f"time (s) from {t0:.1f} s into the condition")
    sel = (t >= t0) & (t < t1)
    for a in ax:
        a.fill_between(t[sel] - t0, 0, 1, where=m["inside"][sel], transform=a.get_xaxis_transform(),
                       color="0.92", zorder=0)
    fig.suptitle(f"{title} - grey: puck inside the fragment")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return t0


def _speed_figure(rows_by_mapping, path):
    mappings = sorted(rows_by_mapping)
    fig, axes = plt.subplots(1, len(mappings), figsize=(4.2 * len(mappings), 3.6), squeeze=False)
    bins = np.geomspace(1, 400, 36)
    for ax, mapping in zip(axes[0], mappings):
        for friction, color in ((False, "tab:blue"), (True, "tab:red")):
            speeds = np.concatenate([r["speeds"] for r in rows_by_mapping[mapping] if r["friction"] == friction]
                                    or [np.zeros(0)])
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


def _coverage_figure(session, measured, path):
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


def binds_statistic(rows):
    """Per mapping and over all: the typical speed in the fragment with friction off minus on, per
    participant (the median of the participant's samples in the fragment: the speed it moved at
    most of the time, which the few fast passes after a release do not pull up), and the paired t
    test over participants (scipy.stats.ttest_rel, two-sided). Returns (table rows, per-participant
    rows)."""
    from scipy import stats
    by = {}
    for r in rows:
        if len(r["speeds"]):
            by.setdefault((r["participant"], r["mapping"]), {})[r["friction"]] = float(np.median(r["speeds"]))
    pairs = [(p, mp, d[False], d[True]) for (p, mp), d in sorted(by.items()) if False in d and True in d]
    table = []
    groups = sorted({mp for _, mp, _, _ in pairs}) + ["all mappings"]
    for group in groups:
        if group == "all mappings":
            per = {}
            for p, _, off, on in pairs:
                per.setdefault(p, []).append((off, on))
            off = np.array([np.mean([a for a, _ in v]) for v in per.values()])
            on = np.array([np.mean([b for _, b in v]) for v in per.values()])
        else:
            off = np.array([a for _, mp, a, _ in pairs if mp == group])
            on = np.array([b for _, mp, _, b in pairs if mp == group])
        n = len(off)
        diff = off - on
        if n >= 2 and np.std(diff) > 0:
            test = stats.ttest_rel(off, on)
            t, p = float(test.statistic), float(test.pvalue)
        else:
            t, p = float("nan"), float("nan")
        table.append(dict(group=group, n=n, mean_off=float(np.mean(off)) if n else float("nan"),
                          mean_on=float(np.mean(on)) if n else float("nan"),
                          mean_difference=float(np.mean(diff)) if n else float("nan"),
                          sd_difference=float(np.std(diff, ddof=1)) if n > 1 else float("nan"), t=t, df=n - 1, p=p))
    return table, pairs


def _write_csv(path, rows, fields):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)


def write_report(root, out_dir):
    """Reads every session under root and writes report.md, its PNGs and CSVs into out_dir.
    Returns a summary dict (the sessions, the rows, the binds table)."""
    root, out_dir = Path(root), Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    all_sessions = study_session.sessions(root)
    rows, md, answers = [], [], []
    study_name = all_sessions[0].manifest["study"]["name"] if all_sessions else "-"
    md += [f"# Study report: {study_name}", "",
           f"{len(all_sessions)} sessions in `{root}`. Speeds come from the device recordings (differences "
           f"over {study_session.SPEED_REPORTS} reports); coverage is the map the experimenter saw, computed "
           "again from the recording; \"in the fragment\" is the fragment's part on the surface.", ""]
    for session in all_sessions:
        measured = []
        md += [f"## Participant {session.participant}", "",
               f"Order: {', '.join(session.manifest['order'])}; seed {session.manifest['seed']}; "
               f"{'finished' if session.finished else 'not finished'}; device {session.manifest['device']['kind']}, "
               f"{session.manifest['sampleRateHz']} Hz.", "",
               "| # | condition | friction | audio | duration (s) | ended by | coverage (live) | coverage (recording) "
               "| median speed in the fragment (mm/s) | time in the fragment (s) | attempts before |",
               "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for c in session.conditions:
            if not c.complete:
                md.append(f"| {c.position} | {c.name} | | | not run to its end | | | | | | {c.attempts} |")
                continue
            m = _measure(session, c)
            measured.append((c, m))
            live = c.event_detail("coverage")
            row = dict(participant=session.participant, position=c.position, condition=c.name,
                       mapping=str(c.settings["mapping"]), friction=bool(c.settings["friction"]),
                       audio=bool(c.settings["audio"]), duration_s=c.duration_s, ended_by=c.ended_by,
                       coverage_live=float(live) if live else float("nan"), coverage_recording=m["coverage"],
                       median_speed_inside=float(np.median(m["speeds_inside"])) if len(m["speeds_inside"]) else float("nan"),
                       mean_speed_inside=float(np.mean(m["speeds_inside"])) if len(m["speeds_inside"]) else float("nan"),
                       time_inside_s=m["time_inside_s"], attempts=c.attempts, speeds=m["speeds_inside"])
            png = f"figure3-{session.participant}-{c.position:02d}-{c.name}.png"
            row["figure3"] = png if _figure3(c, m, out_dir / png, f"{session.participant} {c.name}") is not None else ""
            rows.append(row)
            md.append(f"| {c.position} | {c.name} | {'on' if row['friction'] else 'off'} | "
                      f"{'on' if row['audio'] else 'off'} | {row['duration_s']:.1f} | {row['ended_by']} | "
                      f"{100 * row['coverage_live']:.0f} % | {100 * row['coverage_recording']:.0f} % | "
                      f"{row['median_speed_inside']:.1f} | {row['time_inside_s']:.1f} | {c.attempts} |")
        mine = [r for r in rows if r["participant"] == session.participant]
        if mine:
            speeds_png = f"speeds-{session.participant}.png"
            by = {}
            for r in mine:
                by.setdefault(r["mapping"], []).append(r)
            _speed_figure(by, out_dir / speeds_png)
            md += ["", "Speeds in the fragment, friction off against on:", "", f"![speeds]({speeds_png})"]
        if measured:
            cov_png = f"coverage-{session.participant}.png"
            _coverage_figure(session, measured, out_dir / cov_png)
            md += ["", f"![coverage]({cov_png})", ""]
            md += ["Figure 3 of each condition (4 s of speed, audio and force):", ""]
            md += [f"![{r['condition']}]({r['figure3']})" for r in rows
                   if r["participant"] == session.participant and r["figure3"]]
        session_answers = session.last_answers()
        answers += session_answers
        md += ["", "Answers:", "", "| condition | question | answer | source |", "| --- | --- | --- | --- |"]
        md += [f"| {a['condition']} | {a['question']} | {a['answer'].replace('|', '/')} | {a['source']} |"
               for a in session_answers]
        trials = session.folder / "trials.csv"
        if trials.exists():
            try:
                from . import psychometric  # the threshold procedures' fit (issue 38, "procs")
            except ImportError:
                md += ["", f"Threshold trials in `{trials}`: the fit needs kfharness.psychometric."]
            else:
                md += ["", psychometric.report_section(trials, out_dir, name=session.participant)]
        md.append("")

    by_mapping = {}
    for r in rows:
        by_mapping.setdefault(r["mapping"], []).append(r)
    md += ["## Over all participants", ""]
    if rows:
        _speed_figure(by_mapping, out_dir / "speeds.png")
        md += ["Speed distributions in the fragment, friction off against on, all participants:", "",
               "![speeds](speeds.png)", ""]
    table, pairs = binds_statistic(rows)
    md += ["### Friction binds movement", "",
           "The paper's participants felt raised friction bind their movement (\"getting stuck\", \"syrupy\"). "
           "Measured: each participant's median speed in the fragment with friction off minus on (its typical "
           "speed there), and the paired t test over participants (two-sided, scipy.stats.ttest_rel); over all "
           "mappings, each participant's mean of its three medians.", "",
           "| mappings | participants | median speed off (mm/s) | on (mm/s) | difference (mm/s) | sd | t | df | p |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    md += [f"| {r['group']} | {r['n']} | {r['mean_off']:.1f} | {r['mean_on']:.1f} | {r['mean_difference']:.1f} | "
           f"{r['sd_difference']:.1f} | {r['t']:.2f} | {r['df']} | {r['p']:.3g} |" for r in table]
    md.append("")
    _write_csv(out_dir / "conditions.csv", rows,
               ["participant", "position", "condition", "mapping", "friction", "audio", "duration_s", "ended_by",
                "coverage_live", "coverage_recording", "median_speed_inside", "mean_speed_inside", "time_inside_s",
                "attempts", "figure3"])
    _write_csv(out_dir / "answers.csv", answers, list(answers[0].keys()) if answers else ["participant"])
    _write_csv(out_dir / "binds.csv", [dict(participant=p, mapping=mp, speed_off=a, speed_on=b, difference=a - b)
                                       for p, mp, a, b in pairs],
               ["participant", "mapping", "speed_off", "speed_on", "difference"])
    _write_csv(out_dir / "binds-test.csv", table, list(table[0].keys()) if table else ["group"])
    md += ["Files: `conditions.csv` (a row per condition run), `answers.csv` (the last answer to each question), "
           "`binds.csv` (per participant and mapping), `binds-test.csv` (the test).", ""]
    (out_dir / "report.md").write_text("\n".join(md))
    return dict(sessions=all_sessions, rows=rows, binds=table, pairs=pairs)
