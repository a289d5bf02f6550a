"""The report's text stage: report.md's Markdown from the tidy tables (report_tables), the
statistics (report_statistics) and the figures' file names."""
from . import session_folder
from .report_statistics import BIND_BIN_MM

CONDITIONS_HEADER = ["| # | condition | friction | audio | duration (s) | ended by | coverage (live) | coverage (recording) "
                     "| median speed in the fragment (mm/s) | time in the fragment (s) | attempts before |",
                     "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]


def heading(study_name, count, root):
    return [f"# Study report: {study_name}", "",
            f"{count} sessions in `{root}`. Speeds come from the device recordings (differences "
            f"over {session_folder.SPEED_REPORTS} reports); coverage is the map the experimenter saw, made "
            "from the recording as it was written, and computed again from the whole recording "
            "(`conditions.csv`'s coverage_cells_apart: the cells where the two differ); \"in the "
            "fragment\" is the fragment's part on the surface.", ""]


def unreadable(folder, why):
    return [f"**Not reported: the session in `{folder.name}` cannot be read** ({why}).", ""]


def not_reported(participant, why):
    return [f"## Participant {participant}", "", f"**Not reported: its files cannot be read** ({why}).", ""]


def _condition_line(c, row):
    if row is None:
        return f"| {c.position} | {c.name} | | | not run to its end | | | | | | {c.attempts} |"
    if row["threshold"]:
        return (f"| {c.position} | {c.name} | threshold experiment | | {row['duration_s']:.1f} | "
                f"{row['ended_by']} | | | | | {c.attempts} |")
    return (f"| {c.position} | {c.name} | {'on' if row['friction'] else 'off'} | "
            f"{'on' if row['audio'] else 'off'} | {row['duration_s']:.1f} | {row['ended_by']} | "
            f"{100 * row['coverage_live']:.0f} % | {100 * row['coverage_recording']:.0f} % | "
            f"{row['median_speed_inside']:.1f} | {row['time_inside_s']:.1f} | {c.attempts} |")


def session_section(session, conditions, answers, figures, thresholds):
    """One participant's part: its conditions (rows of the conditions table, by position), the
    names of its speed and coverage figures (figures: dict, empty without exploring conditions),
    its answers (rows) and its threshold section (Markdown, or None without trials)."""
    m = session.manifest
    md = [f"## Participant {session.participant}", "",
          f"Order: {', '.join(m['order'])}; seed {m['seed']}; "
          f"{'finished' if session.finished else 'not finished'}; device {m['device']['kind']}, "
          f"{m['sampleRateHz']} Hz.", ""] + CONDITIONS_HEADER
    by_position = {row["position"]: row for row in conditions}
    md += [_condition_line(c, by_position.get(c.position) if c.complete else None) for c in session.conditions]
    if figures:
        md += ["", "Speeds in the fragment, friction off against on:", "", f"![speeds]({figures['speeds']})"]
        md += ["", f"![coverage]({figures['coverage']})", ""]
    if conditions:
        md += ["Figure 3 of each condition (4 s of speed, audio and force):", ""]
        md += [f"![{r['condition']}]({r['figure3']})" for r in conditions if r["figure3"]]
    md += ["", "Answers:", "", "| condition | question | answer | source |", "| --- | --- | --- | --- |"]
    md += [f"| {a['condition']} | {a['question']} | {a['answer'].replace('|', '/')} | {a['source']} |"
           for a in answers]
    if thresholds is not None:
        md += ["", thresholds]
    if session.damaged:
        md += ["", f"Damaged rows, skipped ({len(session.damaged)}; the rows after each were read):", ""]
        md += [f"- `{row}`" for row in session.damaged]
    md.append("")
    return md


def overall(speeds_png, binds_png, table):
    """Over all participants: the speed figure's name (or None), the binds figure's (or None) and
    the binds test (a DataFrame, a row per mapping)."""
    md = ["## Over all participants", ""]
    if speeds_png:
        md += ["Speed distributions in the fragment, friction off against on, all participants:", "",
               f"![speeds]({speeds_png})", ""]
    md += ["### Friction binds movement", "",
           "The paper's participants felt raised friction bind their movement (\"getting stuck\" in the signal "
           "area of mapping 2 \"would bind them to slower movements\"), and the paper says friction can slow "
           "movement down or speed it up. Measured where the friction is: the parts of the fragment "
           f"({BIND_BIN_MM} mm each) where the mean force commanded with friction on (all participants) lies "
           "above the middle of the device's minimum force and the highest force commanded. Each "
           "participant's median speed there with friction off minus on (the speed it moved at most of the "
           "time there), and the paired t test over participants per mapping (two-sided, "
           "scipy.stats.ttest_rel). A positive difference: slower where the friction is.", ""]
    if binds_png:
        md += [f"![binds]({binds_png})", ""]
    md += ["| mapping | raised (mm of the fragment) | participants | median speed off (mm/s) | on (mm/s) "
           "| difference (mm/s) | sd | t | df | p |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    md += [f"| {r.mapping} | {r.raised_mm:.1f} of {r.area_mm:.1f} | {r.n} | {r.mean_off:.1f} | "
           f"{r.mean_on:.1f} | {r.mean_difference:.1f} | {r.sd_difference:.1f} | {r.t:.2f} | "
           f"{r.df} | {r.p:.3g} |" for r in table.itertuples()]
    md.append("")
    return md


def files(names):
    return ["Files: " + ", ".join(names) + ".", ""]
