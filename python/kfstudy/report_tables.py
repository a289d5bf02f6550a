"""The report's first two stages: the sessions loaded (session_folder) and made into tidy tables
(pandas DataFrames, one row per observation):

- conditions: a row per condition run to its end (the columns of conditions.csv, the fragment's
  area beside them);
- samples: a row per device report of an exploring condition (where the puck was, its speed and
  the force commanded there, and whether it was inside the fragment);
- answers: a row per question, its last answer.

A session whose files cannot be read is left out of every table with the reason (Tables.failed),
so that one participant's damaged files do not cost the others their report.
"""
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from . import session_folder

# conditions.csv's columns, in order.
CONDITION_COLUMNS = ["participant", "position", "condition", "threshold", "mapping", "friction", "audio", "duration_s",
                     "ended_by", "coverage_live", "coverage_recording", "coverage_cells_apart", "median_speed_inside",
                     "mean_speed_inside", "time_inside_s", "attempts", "figure3"]
SAMPLE_COLUMNS = ["participant", "position", "condition", "mapping", "friction", "t_s", "x_mm", "v_mm_s", "force_n",
                  "inside"]
# Errors a session's damaged or missing files raise while it is read.
READ_ERRORS = (OSError, ValueError, KeyError, IndexError, AssertionError)


@dataclass
class Tables:
    sessions: list  # session_folder.StudySession, in the order reported
    unreadable: list  # (folder, why) of sessions that could not be opened at all
    conditions: pd.DataFrame
    samples: pd.DataFrame
    answers: pd.DataFrame
    failed: dict = field(default_factory=dict)  # participant -> why its files could not be read
    # (session, condition, measurement) of every condition run to its end, for the figures.
    measured: list = field(default_factory=list)

    def drop(self, session, why):
        """Leaves a session out of every table, with the reason."""
        p = session.participant
        self.failed[p] = why
        self.conditions = self.conditions[self.conditions.participant != p]
        self.samples = self.samples[self.samples.participant != p]
        self.answers = self.answers[self.answers.participant != p] if len(self.answers) else self.answers
        self.measured = [entry for entry in self.measured if entry[0] is not session]

    def exploring(self):
        return self.conditions[~self.conditions.threshold.astype(bool)]


def measure(session, condition):
    """A condition's track from its device recording: times, positions, speeds, inside the
    fragment, the coverage map, the time spent inside and the force commanded at each report."""
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


def _condition_row(session, c, m):
    base = dict(participant=session.participant, position=c.position, condition=c.name, threshold=c.is_threshold,
                duration_s=c.duration_s, ended_by=c.ended_by, attempts=c.attempts, figure3="")
    if c.is_threshold:
        # Trials, not exploration: its fit is the psychometric stage's; its speeds are no exploring's.
        return base
    live = c.event_detail("coverage")
    live_cells = c.live_cells()
    speeds = m["speeds_inside"]
    return dict(base, mapping=str(c.settings["mapping"]), friction=bool(c.settings["friction"]),
                audio=bool(c.settings["audio"]), coverage_live=float(live) if live else float("nan"),
                coverage_recording=m["coverage"],
                # The cells covered in one map and not in the other; -1: no map logged (older sessions).
                coverage_cells_apart=-1 if live_cells is None else int((live_cells != m["cells"]).sum()),
                median_speed_inside=float(np.median(speeds)) if len(speeds) else float("nan"),
                mean_speed_inside=float(np.mean(speeds)) if len(speeds) else float("nan"),
                time_inside_s=m["time_inside_s"], area_from_mm=float(c.area_mm[0]), area_to_mm=float(c.area_mm[1]))


def _samples(row, m):
    return pd.DataFrame(dict(participant=row["participant"], position=row["position"], condition=row["condition"],
                             mapping=row["mapping"], friction=row["friction"], t_s=m["t"], x_mm=m["x"], v_mm_s=m["v"],
                             force_n=m["force"], inside=m["inside"]), columns=SAMPLE_COLUMNS)


def _session_tables(session):
    """(condition rows, sample frames, answer rows, measured) of one session; raises READ_ERRORS."""
    rows, samples, measured = [], [], []
    for c in session.conditions:
        if not c.complete:
            continue
        m = measure(session, c)
        measured.append((session, c, m))
        row = _condition_row(session, c, m)
        rows.append(row)
        if not c.is_threshold:
            samples.append(_samples(row, m))
    return rows, samples, session.last_answers(), measured


def load(root):
    """Stages 1 and 2: every session under root, read into Tables."""
    unreadable = []
    sessions = session_folder.sessions(root, unreadable)
    rows, samples, answers, measured, failed = [], [], [], [], {}
    for session in sessions:
        try:
            r, s, a, m = _session_tables(session)
        except READ_ERRORS as error:
            failed[session.participant] = f"{type(error).__name__}: {error}"
            continue
        rows += r
        samples += s
        answers += a
        measured += m
    conditions = pd.DataFrame(rows, columns=CONDITION_COLUMNS + ["area_from_mm", "area_to_mm"])
    # A count, blank for the threshold conditions (not 0.0 and NaN, as a float column would be).
    conditions["coverage_cells_apart"] = conditions["coverage_cells_apart"].astype("Int64")
    return Tables(sessions=sessions, unreadable=unreadable, conditions=conditions,
                  samples=pd.concat(samples, ignore_index=True) if samples else pd.DataFrame(columns=SAMPLE_COLUMNS),
                  answers=pd.DataFrame(answers), failed=failed, measured=measured)
