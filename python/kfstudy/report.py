"""The report of a FrictionStudy's sessions, as a pipeline on pandas: load the session folders and
tidy them into tables (report_tables: a row per condition, per device report, per answer), the
statistics (report_statistics: where the friction is raised, the "binds" statistic; psychometric:
the threshold fits), the figures (report_figures: each condition's Figure 3, coverage, speed
distributions, binds) and the text (report_text). Writes report.md with its PNG figures, the tables
as CSV files beside it, and the data as BIDS behavioural data (bids). A session whose files cannot
be read at any stage is left out of every table with the reason; the others are reported."""
import sys
from pathlib import Path

import pandas as pd

from . import bids, psychometric, report_figures, report_statistics, report_tables, report_text
from .report_tables import READ_ERRORS


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


def _participant_figures(tables, session, out_dir):
    """Each of a session's Figure 3s (their names into the conditions table), and its speed and
    coverage figures if it explored: {speeds, coverage} names, or {}."""
    p = session.participant
    for s, c, m in tables.measured:
        if s is session:
            png = f"figure3-{p}-{c.position:02d}-{c.name}.png"
            if report_figures.figure3(c, m, out_dir / png, f"{p} {c.name}") is not None:
                where = (tables.conditions.participant == p) & (tables.conditions.position == c.position)
                tables.conditions.loc[where, "figure3"] = png
    samples = tables.samples[tables.samples.participant == p]
    if not len(samples):
        return {}
    names = dict(speeds=f"speeds-{p}.png", coverage=f"coverage-{p}.png")
    report_figures.speed_figure(samples, out_dir / names["speeds"])
    report_figures.coverage_figure(session, [(c, m) for s, c, m in tables.measured if s is session and not c.is_threshold],
                                   out_dir / names["coverage"])
    return names


def _thresholds(session, out_dir):
    """(Markdown section, fit rows) of a session's threshold conditions, or (None, [])."""
    trials = session.folder / "trials.csv"
    if not trials.exists():
        return None, []
    section, fits = psychometric.report_section(trials, out_dir, session.participant, _threshold_conditions(session),
                                                session.damaged)
    return section, [dict(participant=session.participant, **f) for f in fits]


def _per_session(tables, out_dir):
    """The figures and threshold fits of each session, and its Markdown; a session failing here
    is dropped (Tables.drop). Returns ({participant: Markdown lines}, fits DataFrame)."""
    sections, fits = {}, []
    for session in tables.sessions:
        if session.participant in tables.failed:
            continue
        try:
            figures = _participant_figures(tables, session, out_dir)
            thresholds, session_fits = _thresholds(session, out_dir)
        except READ_ERRORS as error:
            tables.drop(session, f"{type(error).__name__}: {error}")
            continue
        p = session.participant
        conditions = tables.conditions[tables.conditions.participant == p].to_dict("records")
        answers = tables.answers[tables.answers.participant == p].to_dict("records") if len(tables.answers) else []
        sections[p] = report_text.session_section(session, conditions, answers, figures, thresholds)
        fits += session_fits
        for row in session.damaged:
            print(f"kfstudy report: {session.folder}: skipped {row}", file=sys.stderr)
    return sections, pd.DataFrame(fits)


FIT_COLUMNS = ["participant", "condition", "unit", "trials", "threshold", "threshold_se_log10", "slope", "lapse",
               "level_707", "level_794", "log_likelihood", "estimate", "observer_threshold", "warning"]


def write_report(root, out_dir):
    """Reads every session under root and writes report.md, its PNGs and CSVs into out_dir.
    Returns a summary dict: the sessions, and the tables (DataFrames) conditions, binds (the test
    per mapping), pairs (per participant and mapping) and thresholds (the fits)."""
    root, out_dir = Path(root), Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    tables = report_tables.load(root)
    sections, fits = _per_session(tables, out_dir)
    exploring = tables.exploring()
    areas = {m: (r.area_from_mm, r.area_to_mm) for m, r in exploring[exploring.friction.astype(bool)]
             .groupby("mapping").first().iterrows()}
    sessions = tables.sessions
    min_force_n = float(sessions[0].manifest["device"]["specs"]["minForceN"]) if sessions else 0.0
    parts = report_statistics.raised_parts(tables.samples, areas, min_force_n)
    table, pairs = report_statistics.binds(tables.samples, parts)

    speeds_png = binds_png = None
    if len(tables.samples):
        speeds_png = "speeds.png"
        report_figures.speed_figure(tables.samples, out_dir / speeds_png)
    if len(parts):
        binds_png = "binds.png"
        report_figures.binds_figure(tables.samples, parts, out_dir / binds_png)

    md = report_text.heading(sessions[0].manifest["study"]["name"] if sessions else "-", len(sessions), root)
    for folder, why in tables.unreadable:
        md += report_text.unreadable(folder, why)
        print(f"kfstudy report: {folder}: not reported: {why}", file=sys.stderr)
    for session in sessions:
        why = tables.failed.get(session.participant)
        md += report_text.not_reported(session.participant, why) if why else sections[session.participant]
        if why:
            print(f"kfstudy report: {session.folder}: not reported: {why}", file=sys.stderr)
    md += report_text.overall(speeds_png, binds_png, table)

    tables.conditions.to_csv(out_dir / "conditions.csv", columns=report_tables.CONDITION_COLUMNS, index=False)
    tables.answers.to_csv(out_dir / "answers.csv", index=False)
    pairs.to_csv(out_dir / "binds.csv", index=False)
    table.to_csv(out_dir / "binds-test.csv", index=False)
    parts.drop(columns="part").to_csv(out_dir / "binds-parts.csv", index=False)
    names = ["`conditions.csv` (a row per condition run)", "`answers.csv` (the last answer to each question)",
             "`binds.csv` (per participant and mapping)", "`binds-test.csv` (the test)",
             "`binds-parts.csv` (the parts of each fragment and whether the friction is raised there)"]
    if len(fits):
        fits.to_csv(out_dir / "thresholds.csv", columns=FIT_COLUMNS, index=False)
        names.append("`thresholds.csv` (the threshold fits)")
    bids.write(sessions, out_dir / "bids")
    names.append("`bids/` (the data as BIDS behavioural data: a trials and an answers table per participant, each "
                 "column described in its JSON sidecar; `bids/derivatives/kfstudy/` holds the study's tidy trials "
                 "table and the counts per level that psignifit reads)")
    md += report_text.files(names)
    (out_dir / "report.md").write_text("\n".join(md))
    return dict(sessions=sessions, conditions=tables.conditions, binds=table, pairs=pairs, thresholds=fits)
