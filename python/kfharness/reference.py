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
