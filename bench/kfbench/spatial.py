"""SpatialBufRd against BufRd (none, linear, cubic) on the same float positions: the error against
the exact continuous signal and against the same interpolation in double (the index error), for
each pilot mapping at the grid's speeds; and the index precision far from the origin and at
indices about 1e7, read from a buffer holding k mod 16."""
import numpy as np
import soundfile

from kfstudy import readers

from . import scores
from .common import BLOCK, GRID, MAPPINGS, ORIGIN, PILOT_FRAMES, PILOT_PERIOD, SPATIAL_S, SR

INTERP_NAMES = {1: "none", 2: "linear", 4: "cubic"}
FAR_ORIGIN_MM = 1000.0
LONG_INDEX = 10_000_000
LONG_FRAMES = 12_000_000
SPM = MAPPINGS[0]  # the index cases read at mapping 1's samples per mm
FAR_LABEL = f"far origin: {FAR_ORIGIN_MM:g} mm + x, {SPM} samples/mm"
LONG_LABEL = f"long buffer: index ~1e7, {SPM} samples/mm"
CHANNELS = 7 * len(GRID) + 14


def write_buffers(bench):
    """The pilot signal (one cycle per PILOT_PERIOD samples), a mod-16 ramp and a long buffer
    holding k mod 16 around index 1e7 (zeros elsewhere)."""
    k = np.arange(PILOT_FRAMES)
    soundfile.write(bench.work / "pilot.wav", np.sin(2 * np.pi * k / PILOT_PERIOD).astype(np.float32), SR,
                    subtype="FLOAT")
    soundfile.write(bench.work / "ramp16.wav", (k % 16).astype(np.float32), SR, subtype="FLOAT")


def write_long_buffer(bench):
    long = np.zeros(LONG_FRAMES, dtype=np.float32)
    k0 = LONG_INDEX - 5000
    long[k0: k0 + 10_000] = (np.arange(k0, k0 + 10_000) % 16).astype(np.float32)
    soundfile.write(bench.work / "long.wav", long, SR, subtype="FLOAT")


def score_code(bench):
    return scores.code("spatial", seconds=SPATIAL_S, grid_spms=[spm for spm, _ in GRID],
                       grid_speeds=[v for _, v in GRID], cases=len(GRID), frames=PILOT_FRAMES, origin=ORIGIN,
                       far_origin=FAR_ORIGIN_MM, spm=SPM, len=PILOT_FRAMES // SPM, long_mm=LONG_INDEX / SPM,
                       pilot_wav=scores.sc_path(bench.work / "pilot.wav"),
                       ramp_wav=scores.sc_path(bench.work / "ramp16.wav"),
                       long_wav=scores.sc_path(bench.work / "long.wav"), osc=scores.sc_path(bench.work / "spatial.osc"))


def catmull_rom(buf, idx):
    """The 4-point Hermite read of a zero-padded buffer at double index, in double."""
    i = np.floor(idx).astype(np.int64)
    f = idx - i
    pad = np.concatenate([[0.0, 0.0], buf.astype(np.float64), [0.0, 0.0, 0.0]])
    y0, y1, y2, y3 = (pad[np.clip(i + d + 2, 0, len(pad) - 1)] for d in (-1, 0, 1, 2))
    c1 = 0.5 * (y2 - y0)
    c2 = y0 - 2.5 * y1 + 2 * y2 - 0.5 * y3
    c3 = 0.5 * (y3 - y0) + 1.5 * (y1 - y2)
    return ((c3 * f + c2) * f + c1) * f + y1


def linear_read(buf, idx):
    i = np.floor(idx).astype(np.int64)
    f = idx - i
    pad = np.concatenate([[0.0], buf.astype(np.float64), [0.0, 0.0]])
    return pad[np.clip(i + 1, 0, len(pad) - 1)] * (1 - f) + pad[np.clip(i + 2, 0, len(pad) - 1)] * f


def none_read(buf, idx):
    i = np.floor(idx).astype(np.int64)
    pad = np.concatenate([[0.0], buf.astype(np.float64), [0.0]])
    return pad[np.clip(i + 1, 0, len(pad) - 1)]


DOUBLE_READS = {1: none_read, 2: linear_read, 4: catmull_rom}


def _columns(c):
    """(UGen, interp, column) of the six readers of the case starting at column c."""
    for j, interp in enumerate((1, 2, 4)):
        for ugen, col in (("SpatialBufRd", c + 1 + j), ("BufRd", c + 4 + j)):
            yield ugen, interp, col


def _pilot_errors(data, pilot, c, spm):
    pos = data[:, c].astype(np.float64)
    idx = (pos - np.float64(np.float32(ORIGIN))) * np.float64(np.float32(spm))  # what the UGen was given, exactly
    inside = (idx >= 1) & (idx <= PILOT_FRAMES - 3)
    exact = np.sin(2 * np.pi * idx / PILOT_PERIOD)
    entry = {}
    for ugen, interp, col in _columns(c):
        out = data[:, col].astype(np.float64)
        e_exact = np.abs(out - exact)[inside]
        e_same = np.abs(out - DOUBLE_READS[interp](pilot, idx))[inside]
        entry[f"{ugen} {INTERP_NAMES[interp]}"] = {
            "max_vs_signal": float(e_exact.max()), "rms_vs_signal": float(np.sqrt(np.mean(e_exact ** 2))),
            "max_vs_double_read": float(e_same.max()), "rms_vs_double_read": float(np.sqrt(np.mean(e_same ** 2)))}
    entry["samples"] = int(inside.sum())
    return entry


def _index_errors(data, c, origin, frames):
    """The output of a linear or cubic read of k mod 16 is the index mod 16 wherever the taps do
    not straddle a wrap; none gives floor(index) mod 16."""
    pos = data[:, c].astype(np.float64)
    idx = (pos - origin) * SPM
    r = np.floor(idx) % 16
    ok = (r >= 1) & (r <= 13) & (idx >= 1) & (idx <= frames - 3)
    ulp = float(np.spacing(np.float32(np.abs(pos).max())))
    entry = {"index_min": float(idx.min()), "index_max": float(idx.max()), "position_ulp_mm": ulp,
             "index_step_from_position_ulp": ulp * SPM}
    traces = {}
    for ugen, interp, col in _columns(c):
        out = data[:, col].astype(np.float64)
        if interp == 1:
            d = ((out - (np.floor(idx) % 16) + 8) % 16 - 8)[ok]
            entry[f"{ugen} none"] = {"max_index_error": float(np.abs(d).max()),
                                     "wrong_sample_fraction": float(np.mean(d != 0))}
        else:
            d = ((out - (idx % 16) + 8) % 16 - 8)[ok]
            entry[f"{ugen} {INTERP_NAMES[interp]}"] = {"max_index_error": float(np.abs(d).max()),
                                                       "rms_index_error": float(np.sqrt(np.mean(d ** 2)))}
            if interp == 4:
                traces[ugen] = (np.nonzero(ok)[0], d)
    entry["_traces"] = traces  # for the plot; not written to results.json
    return entry


def analyse(bench):
    data, rate = readers.read_wav(bench.work / "spatial.wav")
    assert rate == SR and data.shape[1] == CHANNELS
    data = data[BLOCK:]  # the first block holds the constructors' initial values
    pilot = readers.read_wav(bench.work / "pilot.wav")[0][:, 0]
    res = {"pilot": {}, "index": {}}
    for k, (spm, speed) in enumerate(GRID):
        entry = _pilot_errors(data, pilot, 7 * k, spm)
        entry.update(spm=spm, speed=speed)
        res["pilot"][f"pilot {spm} samples/mm, {speed} mm/s"] = entry
    g = 7 * len(GRID)
    res["index"][FAR_LABEL] = _index_errors(data, g, FAR_ORIGIN_MM, PILOT_FRAMES)
    res["index"][LONG_LABEL] = _index_errors(data, g + 7, 0.0, LONG_FRAMES)
    return res
