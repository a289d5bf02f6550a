"""Numeric references, computed in double precision from the definitions, for the tests and the
benchmarks to compare the UGens against."""
import numpy as np

from . import profile


def equations_1_and_2(a, n, **mapping):
    """Force per sample (N) from the paper's equations: (1) the mean |a| over the latest n samples
    (silence before the start), (2) in dB, clipped and mapped as force_of_mean. NaN counts as
    silence and Inf as the loudest level, as LoudnessToFriction documents."""
    a = np.abs(np.asarray(a, dtype=np.float64))
    a = np.where(np.isnan(a), 0.0, np.where(np.isinf(a), 1e30, a))
    # A direct sum per window (no running sum: an Inf sample would wreck one in double).
    mean = np.convolve(a, np.ones(n))[: len(a)] / n
    return force_of_mean(mean, **mapping)


def force_of_mean(mean, lo_db=None, hi_db=None, lo_force_n=None, hi_force_n=None, ref=None):
    """Equation (2) for a mean |a| (a number or an array): 20 log10(mean / ref) clipped to
    [lo_db, hi_db], mapped linearly onto [lo_force_n, hi_force_n]. Defaults: the paper's mapping."""
    m = profile.mapping()
    lo_db = m["loDb"] if lo_db is None else lo_db
    hi_db = m["hiDb"] if hi_db is None else hi_db
    lo_force_n = m["loForceN"] if lo_force_n is None else lo_force_n
    hi_force_n = m["hiForceN"] if hi_force_n is None else hi_force_n
    ref = m["ref"] if ref is None else ref
    with np.errstate(divide="ignore"):
        db = 20 * np.log10(np.asarray(mean, dtype=np.float64) / ref)
    db = np.clip(db, lo_db, hi_db)
    return lo_force_n + (db - lo_db) / (hi_db - lo_db) * (hi_force_n - lo_force_n)


def rising_crossings(x):
    """Rising zero crossings, located to a fraction of a sample."""
    x = np.asarray(x, dtype=np.float64)
    idx = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    return idx + (-x[idx]) / (x[idx + 1] - x[idx])


def zero_crossing_frequency(x, sample_rate):
    """Frequency from the mean spacing of rising zero crossings."""
    crossings = rising_crossings(x)
    assert len(crossings) >= 3, "too few zero crossings"
    return sample_rate * (len(crossings) - 1) / (crossings[-1] - crossings[0])


def _tap_weights(t, mode):
    """Weights of the taps at whole part - 1 .. + 2 for fractions t (SpatialBufRd2D's modes:
    1 none, 2 linear, 4 cubic Catmull-Rom in its matrix form)."""
    z = np.zeros_like(t)
    if mode == 1:
        return [z, z + 1, z, z]
    if mode == 2:
        return [z, 1 - t, t, z]
    return [0.5 * (-t + 2 * t**2 - t**3), 0.5 * (2 - 5 * t**2 + 3 * t**3), 0.5 * (t + 4 * t**2 - 3 * t**3),
            0.5 * (-t**2 + t**3)]


def surface(matrix, column, row, mode=4):
    """SpatialBufRd2D's definition in double: the matrix (rows x columns) zero outside its samples,
    read at fractional column and row indices; exactly 0 outside (-1, size) in either axis and for
    NaN/Inf."""
    matrix = np.asarray(matrix, dtype=np.float64)
    height, width = matrix.shape
    column, row = np.asarray(column, dtype=np.float64), np.asarray(row, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        inside = (column > -1) & (column < width) & (row > -1) & (row < height)
    c = np.where(inside, column, 0.0)
    r = np.where(inside, row, 0.0)
    i, j = np.floor(c).astype(np.int64), np.floor(r).astype(np.int64)
    padded = np.pad(matrix, 3)  # taps reach two beyond any inside index
    wx, wy = _tap_weights(c - i, mode), _tap_weights(r - j, mode)
    out = np.zeros_like(c)
    for b in range(4):
        for a in range(4):
            out += wy[b] * wx[a] * padded[j - 1 + b + 3, i - 1 + a + 3]
    return np.where(inside, out, 0.0)
