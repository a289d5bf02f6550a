"""Readers of the files the system writes: WAV renders and kf-session recordings
(docs/record-format.md)."""
from pathlib import Path

import numpy as np
import soundfile


def read_text(path):
    """A text file's text; a file that is not UTF-8 (damaged) raises ValueError naming it."""
    try:
        return Path(path).read_text()
    except UnicodeDecodeError as error:
        raise ValueError(f"{path}: not UTF-8 text at byte {error.start} (damaged?)") from error


def read_wav(path):
    """(frames x channels float32, sample rate)."""
    data, rate = soundfile.read(str(path), dtype="float32", always_2d=True)
    return data, rate


def read_session(path):
    """(header dict, [(tag, fields)...]) of a kf-session file, records in file order. Fields are
    floats, but for an off record's cause (O: [hostTimeS, cause]; cause "" in files written
    before it was recorded)."""
    lines = read_text(path).splitlines()
    assert lines and lines[0].startswith("kf-session 1 "), f"not a kf-session file: {path}"
    header = dict(field.split("=", 1) for field in lines[0].split()[2:])
    records = []
    for line in lines[1:]:
        if not line.strip() or line.startswith("#"):
            continue
        tag, *fields = line.split()
        if tag == "O":
            records.append((tag, [float(fields[0]), fields[1] if len(fields) > 1 else ""]))
        else:
            records.append((tag, [float(f) for f in fields]))
    return header, records


class Session:
    """A kf-session file as arrays: `reports` (R: hostTimeS deviceTimeS dxCounts dyCounts buttons
    flags), `frames` (F: hostTimeS frameTimeS requestedForceN commandedForceN), `offs` (O times) and
    `off_causes` (why each: stop, quit, close, watchdog, failure, signal, client)."""

    def __init__(self, path):
        self.header, records = read_session(path)
        self.reports = np.array([f for tag, f in records if tag == "R"]).reshape(-1, 6)
        self.frames = np.array([f for tag, f in records if tag == "F"]).reshape(-1, 4)
        self.offs = [f[0] for tag, f in records if tag == "O"]
        self.off_causes = [f[1] for tag, f in records if tag == "O"]
