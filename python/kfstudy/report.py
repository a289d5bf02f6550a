"""The report of a FrictionStudy's sessions (session_folder reads them): per participant and over
all, the conditions in the order run, their durations, the coverage reached, the speed
distributions per condition (friction off against on), the answers, each condition's Figure 3 (4 s
of speed, audio and force), the "binds" statistic (the paper's observation that raised friction
binds movement: the speed where the friction is raised, with friction off minus on, per
participant and mapping, and a paired t test over participants per mapping), and the threshold
fits of any threshold conditions (psychometric). Markdown with PNG figures and CSV files beside it.
"""
import csv
import sys
from pathlib import Path

import numpy as np

from . import bids, session_folder

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIGURE3_S = 4.0


def _measure(session, condition):
    t, x, v = condition.track()
    inside = (x >= condition.area_mm[0]) & (x < condition.area_mm[1])
    cells = session_folder.coverage(x, v, condition.area_mm, session.coverage_settings)
    period = np.median(np.diff(t)) if len(t) > 1 else 0.0
    tf, force = condition.forces()
    return dict(t=t, x=x, v=v, inside=inside, cells=cells,
                coverage=float(cells.mean()) if cells.size else 0.0,
                speeds_inside=np.abs(v[inside]), time_inside_s=float(inside.sum() * period),
                # The force the magnet was commanded where the speed was measured.
                force=np.interp(t, tf, force) if len(tf) else np.full(len(t), np.nan))


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


# "Where the friction is": a part of the fragment BIND_BIN_MM wide is raised when the mean force
# commanded there, over every friction-on condition of its mapping (all participants), lies above
# the middle between the device's minimum force and the highest force those conditions commanded
# (their 99th percentile). 0.5 mm resolves mapping 3's force bumps (two per 12.5 mm cycle); a
# part needs BIND_MIN_REPORTS reports of friction on to be judged.
BIND_BIN_MM = 0.5
BIND_MIN_REPORTS = 5


def raised_parts(rows, min_force_n):
    """Per mapping: (edges of the parts in mm, mean force per part (N, nan where unseen), raised per
    part (bool)), from the friction-on rows of that mapping."""
    out = {}
    for mapping in sorted({r["mapping"] for r in rows}):
        on = [r for r in rows if r["mapping"] == mapping and r["friction"]]
        if not on:
            continue
        area = on[0]["area_mm"]
        edges = np.arange(area[0], area[1] + BIND_BIN_MM / 2, BIND_BIN_MM)
        x = np.concatenate([r["x"] for r in on])
        force = np.concatenate([r["force"] for r in on])
        part = np.digitize(x, edges) - 1
        seen = (part >= 0) & (part < len(edges) - 1) & np.isfinite(force)
        counts = np.bincount(part[seen], minlength=len(edges) - 1)
        sums = np.bincount(part[seen], weights=force[seen], minlength=len(edges) - 1)
        mean = np.where(counts >= BIND_MIN_REPORTS, sums / np.maximum(counts, 1), np.nan)
        top = np.percentile(force[seen], 99) if seen.any() else np.nan
        out[mapping] = (edges, mean, mean > (min_force_n + top) / 2)
    return out


def speeds_where_raised(row, parts):
    """|speed| (mm/s) of a row's samples in the raised parts of its mapping."""
    edges, _, raised = parts
    part = np.digitize(row["x"], edges) - 1
    inside = (part >= 0) & (part < len(raised))
    where = np.zeros(len(part), dtype=bool)
    where[inside] = raised[part[inside]]
    return np.abs(row["v"][where])


def binds_statistic(rows, parts):
    """Per mapping: the typical speed where the friction is raised (raised_parts) with friction off
    minus on, per participant (the median of the participant's samples there: the speed it moved
    at most of the time, which the few fast passes after a release do not pull up), and the paired
    t test over participants (scipy.stats.ttest_rel, two-sided). Returns (table rows,
    per-participant rows (participant, mapping, off, on))."""
    from scipy import stats
    by = {}
    for r in rows:
        if r["mapping"] not in parts:
            continue
        speeds = speeds_where_raised(r, parts[r["mapping"]])
        if len(speeds):
            by.setdefault((r["participant"], r["mapping"]), {})[r["friction"]] = float(np.median(speeds))
    pairs = [(p, mp, d[False], d[True]) for (p, mp), d in sorted(by.items()) if False in d and True in d]
    table = []
    for mapping in sorted({mp for _, mp, _, _ in pairs}):
        off = np.array([a for _, mp, a, _ in pairs if mp == mapping])
        on = np.array([b for _, mp, _, b in pairs if mp == mapping])
        n = len(off)
        diff = off - on
        if n >= 2 and np.std(diff) > 0:
            test = stats.ttest_rel(off, on)
            t, p = float(test.statistic), float(test.pvalue)
        else:
            t, p = float("nan"), float("nan")
        edges, _, raised = parts[mapping]
        table.append(dict(mapping=mapping, raised_mm=float(raised.sum() * BIND_BIN_MM),
                          area_mm=float(edges[-1] - edges[0]), n=n, mean_off=float(np.mean(off)),
                          mean_on=float(np.mean(on)), mean_difference=float(np.mean(diff)),
                          sd_difference=float(np.std(diff, ddof=1)) if n > 1 else float("nan"), t=t, df=n - 1, p=p))
    return table, pairs


def _binds_figure(rows, parts, path):
    """Per mapping: the mean force commanded along the fragment (friction on, the raised parts
    shaded) over the median speed there with friction off and on (all participants)."""
    mappings = sorted(parts)
    fig, axes = plt.subplots(2, len(mappings), figsize=(4.2 * len(mappings), 5), sharex="col", squeeze=False)
    for k, mapping in enumerate(mappings):
        edges, mean, raised = parts[mapping]
        mid = (edges[:-1] + edges[1:]) / 2
        force_ax, speed_ax = axes[0][k], axes[1][k]
        force_ax.plot(mid, mean, color="k", lw=0.8)
        for ax in (force_ax, speed_ax):
            ax.fill_between(mid, 0, 1, where=raised, step="mid", transform=ax.get_xaxis_transform(),
                            color="0.9", zorder=0)
        force_ax.set_title(mapping)
        force_ax.set_ylabel("mean force, friction on (N)")
        for friction, color in ((False, "tab:blue"), (True, "tab:red")):
            chosen = [r for r in rows if r["mapping"] == mapping and r["friction"] == friction]
            if not chosen:
                continue
            x = np.concatenate([r["x"] for r in chosen])
            v = np.abs(np.concatenate([r["v"] for r in chosen]))
            part = np.digitize(x, edges) - 1
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


def _write_csv(path, rows, fields):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)



def _threshold_conditions(session):
    """Per threshold condition of a session: its unit, the procedure's estimate and the model
    observer of a simulated participant, from the condition's events."""
    known = {}
    for c in session.conditions:
        if c.is_threshold:
            experiment = c.event_json("experiment") or {}
            known[c.name] = dict(unit=bids.LEVEL_UNITS.get(experiment.get("kind"), ""), estimate=c.event_json("estimate"),
                                 observer=c.event_json("observer"))
    return known


def _session_section(session, out_dir, rows, answers, fits):
    """One participant's part of the report: its Markdown lines; its rows, answers and fits
    appended to the lists given."""
    from . import psychometric

    md = []
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
        png = f"figure3-{session.participant}-{c.position:02d}-{c.name}.png"
        figure3 = png if _figure3(c, m, out_dir / png, f"{session.participant} {c.name}") is not None else ""
        if c.is_threshold:
            # Trials, not exploration: its fit is below; its speeds are no exploring's.
            duration = c.duration_s
            md.append(f"| {c.position} | {c.name} | threshold experiment | | {duration:.1f} | "
                      f"{c.ended_by} | | | | | {c.attempts} |")
            rows.append(dict(participant=session.participant, position=c.position, condition=c.name,
                             threshold=True, duration_s=duration, ended_by=c.ended_by, attempts=c.attempts,
                             figure3=figure3))
            continue
        live = c.event_detail("coverage")
        row = dict(participant=session.participant, position=c.position, condition=c.name, threshold=False,
                   mapping=str(c.settings["mapping"]), friction=bool(c.settings["friction"]),
                   audio=bool(c.settings["audio"]), duration_s=c.duration_s, ended_by=c.ended_by,
                   coverage_live=float(live) if live else float("nan"), coverage_recording=m["coverage"],
                   median_speed_inside=float(np.median(m["speeds_inside"])) if len(m["speeds_inside"]) else float("nan"),
                   mean_speed_inside=float(np.mean(m["speeds_inside"])) if len(m["speeds_inside"]) else float("nan"),
                   time_inside_s=m["time_inside_s"], attempts=c.attempts, speeds=m["speeds_inside"],
                   x=m["x"], v=m["v"], force=m["force"], area_mm=c.area_mm, figure3=figure3)
        rows.append(row)
        md.append(f"| {c.position} | {c.name} | {'on' if row['friction'] else 'off'} | "
                  f"{'on' if row['audio'] else 'off'} | {row['duration_s']:.1f} | {row['ended_by']} | "
                  f"{100 * row['coverage_live']:.0f} % | {100 * row['coverage_recording']:.0f} % | "
                  f"{row['median_speed_inside']:.1f} | {row['time_inside_s']:.1f} | {c.attempts} |")
    mine = [r for r in rows if r["participant"] == session.participant]
    exploring = [r for r in mine if not r["threshold"]]
    if exploring:
        speeds_png = f"speeds-{session.participant}.png"
        by = {}
        for r in exploring:
            by.setdefault(r["mapping"], []).append(r)
        _speed_figure(by, out_dir / speeds_png)
        md += ["", "Speeds in the fragment, friction off against on:", "", f"![speeds]({speeds_png})"]
        cov_png = f"coverage-{session.participant}.png"
        _coverage_figure(session, [(c, m) for c, m in measured if not c.is_threshold], out_dir / cov_png)
        md += ["", f"![coverage]({cov_png})", ""]
    if mine:
        md += ["Figure 3 of each condition (4 s of speed, audio and force):", ""]
        md += [f"![{r['condition']}]({r['figure3']})" for r in mine if r["figure3"]]
    session_answers = session.last_answers()
    answers += session_answers
    md += ["", "Answers:", "", "| condition | question | answer | source |", "| --- | --- | --- | --- |"]
    md += [f"| {a['condition']} | {a['question']} | {a['answer'].replace('|', '/')} | {a['source']} |"
           for a in session_answers]
    trials = session.folder / "trials.csv"
    if trials.exists():
        section, session_fits = psychometric.report_section(trials, out_dir, session.participant,
                                                            _threshold_conditions(session), session.damaged)
        md += ["", section]
        fits += [dict(participant=session.participant, **f) for f in session_fits]
    if session.damaged:
        md += ["", f"Damaged rows, skipped ({len(session.damaged)}; the rows after each were read):", ""]
        md += [f"- `{row}`" for row in session.damaged]
        for row in session.damaged:
            print(f"kfstudy report: {session.folder}: skipped {row}", file=sys.stderr)
    md.append("")
    return md


def write_report(root, out_dir):
    """Reads every session under root and writes report.md, its PNGs and CSVs into out_dir.
    Returns a summary dict (the sessions, the rows, the binds table, the threshold fits)."""
    root, out_dir = Path(root), Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    unreadable = []
    all_sessions = session_folder.sessions(root, unreadable)
    rows, md, answers, fits = [], [], [], []
    study_name = all_sessions[0].manifest["study"]["name"] if all_sessions else "-"
    md += [f"# Study report: {study_name}", "",
           f"{len(all_sessions)} sessions in `{root}`. Speeds come from the device recordings (differences "
           f"over {session_folder.SPEED_REPORTS} reports); coverage is the map the experimenter saw, computed "
           "again from the recording; \"in the fragment\" is the fragment's part on the surface.", ""]
    for folder, why in unreadable:
        md += [f"**Not reported: the session in `{folder.name}` cannot be read** ({why}).", ""]
        print(f"kfstudy report: {folder}: not reported: {why}", file=sys.stderr)
    for session in all_sessions:
        kept = len(rows), len(answers), len(fits)
        try:
            md += _session_section(session, out_dir, rows, answers, fits)
        except (OSError, ValueError, KeyError, IndexError, AssertionError) as error:
            # One participant's damaged files must not cost the others their report.
            del rows[kept[0]:], answers[kept[1]:], fits[kept[2]:]
            why = f"{type(error).__name__}: {error}"
            md += [f"## Participant {session.participant}", "", f"**Not reported: its files cannot be read** ({why}).", ""]
            print(f"kfstudy report: {session.folder}: not reported: {why}", file=sys.stderr)

    exploring = [r for r in rows if not r["threshold"]]
    by_mapping = {}
    for r in exploring:
        by_mapping.setdefault(r["mapping"], []).append(r)
    md += ["## Over all participants", ""]
    if exploring:
        _speed_figure(by_mapping, out_dir / "speeds.png")
        md += ["Speed distributions in the fragment, friction off against on, all participants:", "",
               "![speeds](speeds.png)", ""]
    min_force_n = float(all_sessions[0].manifest["device"]["specs"]["minForceN"]) if all_sessions else 0.0
    parts = raised_parts(exploring, min_force_n)
    table, pairs = binds_statistic(exploring, parts)
    md += ["### Friction binds movement", "",
           "The paper's participants felt raised friction bind their movement (\"getting stuck\" in the signal "
           "area of mapping 2 \"would bind them to slower movements\"), and the paper says friction can slow "
           "movement down or speed it up. Measured where the friction is: the parts of the fragment "
           f"({BIND_BIN_MM} mm each) where the mean force commanded with friction on (all participants) lies "
           "above the middle of the device's minimum force and the highest force commanded. Each "
           "participant's median speed there with friction off minus on (the speed it moved at most of the "
           "time there), and the paired t test over participants per mapping (two-sided, "
           "scipy.stats.ttest_rel). A positive difference: slower where the friction is.", ""]
    if parts:
        _binds_figure(exploring, parts, out_dir / "binds.png")
        md += ["![binds](binds.png)", ""]
    md += ["| mapping | raised (mm of the fragment) | participants | median speed off (mm/s) | on (mm/s) "
           "| difference (mm/s) | sd | t | df | p |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    md += [f"| {r['mapping']} | {r['raised_mm']:.1f} of {r['area_mm']:.1f} | {r['n']} | {r['mean_off']:.1f} | "
           f"{r['mean_on']:.1f} | {r['mean_difference']:.1f} | {r['sd_difference']:.1f} | {r['t']:.2f} | "
           f"{r['df']} | {r['p']:.3g} |" for r in table]
    md.append("")
    _write_csv(out_dir / "conditions.csv", rows,
               ["participant", "position", "condition", "threshold", "mapping", "friction", "audio", "duration_s",
                "ended_by", "coverage_live", "coverage_recording", "median_speed_inside", "mean_speed_inside",
                "time_inside_s", "attempts", "figure3"])
    _write_csv(out_dir / "answers.csv", answers, list(answers[0].keys()) if answers else ["participant"])
    _write_csv(out_dir / "binds.csv", [dict(participant=p, mapping=mp, speed_off=a, speed_on=b, difference=a - b)
                                       for p, mp, a, b in pairs],
               ["participant", "mapping", "speed_off", "speed_on", "difference"])
    _write_csv(out_dir / "binds-test.csv", table, list(table[0].keys()) if table else ["mapping"])
    _write_csv(out_dir / "binds-parts.csv",
               [dict(mapping=mapping, from_mm=a, to_mm=b, mean_force_n=f, raised=bool(r))
                for mapping, (edges, mean, raised) in sorted(parts.items())
                for a, b, f, r in zip(edges[:-1], edges[1:], mean, raised)],
               ["mapping", "from_mm", "to_mm", "mean_force_n", "raised"])
    files = ["`conditions.csv` (a row per condition run)", "`answers.csv` (the last answer to each question)",
             "`binds.csv` (per participant and mapping)", "`binds-test.csv` (the test)",
             "`binds-parts.csv` (the parts of each fragment and whether the friction is raised there)"]
    if fits:
        _write_csv(out_dir / "thresholds.csv", fits,
                   ["participant", "condition", "unit", "trials", "threshold", "threshold_se_log10", "slope", "lapse",
                    "level_707", "level_794", "log_likelihood", "estimate", "observer_threshold", "warning"])
        files.append("`thresholds.csv` (the threshold fits)")
    bids.write(all_sessions, out_dir / "bids")
    files.append("`bids/` (the data as BIDS behavioural data: a trials and an answers table per participant, each "
                 "column described in its JSON sidecar; `bids/derivatives/kfstudy/` holds the study's tidy trials "
                 "table and the counts per level that psignifit reads)")
    md += ["Files: " + ", ".join(files) + ".", ""]
    (out_dir / "report.md").write_text("\n".join(md))
    return dict(sessions=all_sessions, rows=rows, binds=table, pairs=pairs, thresholds=fits)
