"""A FrictionStudy session folder read back (FrictionStudySession writes it): the manifest,
the answers, and per condition its events, device recording and audio, with the measurements the
report makes on them (positions and speeds from the recording, coverage as FrictionStudyCoverage
computes it live, the time inside the fragment).

Times: the events are seconds from the condition's start as sclang's clock had them; a recording's
hostTimeS counts from when the device was opened (a simulated participant's device is opened for
each condition, just before its recording starts), so the recording's first line is placed at
the event recordDevice. The audio's first sample is placed at the event recordAudio.
"""
import functools
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import checked_csv, readers

# Speeds are differences of positions over this many reports (5 x 8 ms = 40 ms at 125 Hz): one
# report moves at most by whole counts (0.021 mm, 2.6 mm/s at 125 Hz), so a single report's
# speed is a staircase of 2.6 mm/s steps at slow speeds.
SPEED_REPORTS = 5

# The events a condition's events.csv and a session's session.csv may hold: the same names as
# FrictionStudySession.conditionEvents and .sessionEvents, which its log refuses any other name
# with (tests/scenes/test_session_events.py holds the two lists together).
CONDITION_EVENTS = ("prepare", "recordDevice", "recordAudio", "experiment", "observer", "continue", "start",
                    "pause", "resume", "trial", "done", "maxTime", "repeat", "abort", "lost", "coverage",
                    "coverageMap", "estimate", "answer", "end")
SESSION_EVENTS = ("start", "resume", "finish", "abort", "error")


def read_csv(path, damaged=None):
    """A study CSV's rows as dicts; damaged rows are skipped and listed in `damaged`."""
    return checked_csv.read_rows(path, damaged)


@dataclass
class Condition:
    position: int          # its place in the participant's order, from 1
    name: str
    folder: Path
    settings: dict         # the scene (mapping, friction, audio, origin, ...)
    area_mm: tuple         # the fragment's part on the surface
    events: list = field(default_factory=list)
    attempts: int = 0      # earlier attempts kept beside it (a crash, a kill, a repeat)
    is_threshold: bool = False  # a threshold experiment's trials, not free exploration

    def event_time(self, name):
        assert name in CONDITION_EVENTS, name
        times = [float(e["timeS"]) for e in self.events if e["event"] == name]
        return times[-1] if times else None

    def event_detail(self, name):
        assert name in CONDITION_EVENTS, name
        details = [e["detail"] for e in self.events if e["event"] == name]
        return details[-1] if details else None

    def event_json(self, name):
        """The detail of the last event name, read as JSON (the threshold conditions' experiment,
        observer and estimate), or None."""
        detail = self.event_detail(name)
        return json.loads(detail) if detail else None

    @property
    def complete(self):
        return self.event_time("end") is not None

    @property
    def start_s(self):
        return self.event_time("start")

    @property
    def stop_s(self):
        for name in ("done", "maxTime"):
            if self.event_time(name) is not None:
                return self.event_time(name)
        return None

    @property
    def duration_s(self):
        return None if self.start_s is None or self.stop_s is None else self.stop_s - self.start_s

    @property
    def ended_by(self):
        return self.event_detail("done") or ("time" if self.event_time("maxTime") is not None else None)

    def live_cells(self):
        """The coverage map the experimenter saw (its coverageMap event), shaped as coverage()'s
        (positionBins x speedBins, True where covered), or None before it was logged."""
        detail = self.event_detail("coverageMap")
        if not detail:
            return None
        return np.array([[c == "1" for c in row] for row in detail.split("/")], dtype=bool).T

    @functools.cached_property
    def recording(self):
        """The device recording (readers.Session), read once."""
        return readers.Session(self.folder / "device.kfsession")

    def track(self):
        """(t, x, speed) of the recording between start and stop, one sample per report: speed in
        mm/s (signed) over SPEED_REPORTS reports, t (s from the condition's start) and x (mm from
        where the device was when recording began) at the middle of those reports, so that a speed
        goes with the place where the puck moved at it."""
        session = self.recording
        count_mm = float(session.header["countMm"])
        r = session.reports
        if len(r) < SPEED_REPORTS + 2:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        # The mouse's own timestamps (deviceTimeS): one report every 8 ms, where the device thread's
        # hostTimeS gives several reports handled in one pump the same time.
        t = r[:, 1] - r[0, 1] + (self.event_time("recordDevice") or 0.0)
        x = np.cumsum(r[:, 2]) * count_mm
        k = SPEED_REPORTS
        dt = t[k:] - t[:-k]
        speed = np.where(dt > 0, (x[k:] - x[:-k]) / np.where(dt > 0, dt, 1.0), np.nan)
        t, x = (t[k:] + t[:-k]) / 2, (x[k:] + x[:-k]) / 2
        keep = ~np.isnan(speed) & (t >= (self.start_s or 0.0)) & (t <= (self.stop_s or np.inf))
        return t[keep], x[keep], speed[keep]

    def forces(self):
        """(t, commanded force N) of the recording's frames, t as in track()."""
        session = self.recording
        f = session.frames
        if len(f) == 0:
            return np.zeros(0), np.zeros(0)
        t0 = session.reports[0, 0] if len(session.reports) else f[0, 0]
        return f[:, 0] - t0 + (self.event_time("recordDevice") or 0.0), f[:, 3]

    def audio(self):
        """(t, left channel) of audio.wav, t as in track()."""
        data, rate = readers.read_wav(self.folder / "audio.wav")
        return np.arange(len(data)) / rate + (self.event_time("recordAudio") or 0.0), data[:, 0]


def coverage(x, speed, area_mm, settings):
    """The map FrictionStudyCoverage keeps (positionBins x speedBins, True where covered): a cell
    is covered when the puck moved through its part of the area at its speed, between two samples
    in a row as well as at one."""
    bins_x, bins_v = int(settings["positionBins"]), int(settings["speedBins"])
    slow, fast = float(settings["slowMmPerS"]), float(settings["fastMmPerS"])
    lo_mm, hi_mm = area_mm
    cells = np.zeros((bins_x, bins_v), dtype=bool)
    if len(x) == 0:
        return cells
    v = np.abs(speed)
    moving = (v >= slow) & (v < fast)
    row = np.floor(np.log(np.where(moving, v, slow) / slow) / np.log(fast / slow) * bins_v).astype(int)
    start = np.concatenate([x[:1], x[:-1]])
    a, b = np.minimum(start, x), np.maximum(start, x)
    crossing = moving & (b >= lo_mm) & (a < hi_mm)

    def column(mm):
        return np.clip(np.floor((np.clip(mm, lo_mm, hi_mm) - lo_mm) / (hi_mm - lo_mm) * bins_x).astype(int),
                       0, bins_x - 1)

    for first, last, k in zip(column(a[crossing]), column(b[crossing]), np.clip(row[crossing], 0, bins_v - 1)):
        cells[first:last + 1, k] = True
    return cells


class StudySession:
    """One participant's folder."""

    def __init__(self, folder):
        self.folder = Path(folder)
        self.damaged = []  # checked_csv.DamagedRow of every row skipped in its CSVs
        self.manifest = json.loads(readers.read_text(self.folder / "manifest.json"))
        self.participant = self.manifest["participant"]
        answers = self.folder / "answers.csv"
        self.answers = read_csv(answers, self.damaged) if answers.exists() else []
        session_log = self.folder / "session.csv"
        self.log = read_csv(session_log, self.damaged) if session_log.exists() else []
        by_name = {c["name"]: c for c in self.manifest["study"]["conditions"]}
        self.conditions = []
        for position, name in enumerate(self.manifest["order"], start=1):
            # Attempt 1 is NN-name, then NN-name-attempt2, ...: the last is the condition's.
            base = self.folder / f"{position:02d}-{name}"
            n = 1
            while (self.folder / f"{base.name}-attempt{n + 1}").exists():
                n += 1
            folder = base if n == 1 else self.folder / f"{base.name}-attempt{n}"
            scene = by_name[name]["scene"]
            area_mm = tuple(float(v) for v in by_name[name]["areaMm"])
            condition = Condition(position, name, folder, scene, area_mm, attempts=n - 1,
                                  is_threshold=bool(by_name[name].get("threshold")))
            if (folder / "events.csv").exists():
                condition.events = read_csv(folder / "events.csv", self.damaged)
            self.conditions.append(condition)

    @property
    def coverage_settings(self):
        return self.manifest["study"]["coverage"]

    @property
    def finished(self):
        return any(e["event"] == "finish" for e in self.log)

    def last_answers(self):
        """The answers of the last attempt of each (condition, question), in the order given."""
        last = {}
        for row in self.answers:
            last[(row["condition"], row["question"])] = row
        return list(last.values())


def sessions(root, unreadable=None):
    """Every session folder under root (a folder with manifest.json), by participant code. A
    folder that cannot be read (its manifest damaged, say) is left out and, with `unreadable` (a
    list), listed there as (folder, why): the others are still read."""
    found = []
    for manifest in sorted(Path(root).glob("*/manifest.json")):
        try:
            found.append(StudySession(manifest.parent))
        except (OSError, ValueError, KeyError, TypeError) as error:
            if unreadable is None:
                raise
            unreadable.append((manifest.parent, f"{type(error).__name__}: {error}"))
    return found
