"""LoudnessToFriction against the built-in chains (RunningSum and Amplitude, each mapped by
equation (2) in UGens), all compared with equations (1) and (2) in double."""
import numpy as np

from kfharness import reference
from kfstudy import readers

from . import scores
from .common import LOUDNESS_IN_SC, LTF_N, MAPPING, SR, amplitude_chain_sc, running_sum_chain_sc

SECONDS = 8.0
CHAINS = [("LoudnessToFriction", 1), ("RunningSum chain", 2), ("Amplitude chain", 3)]  # name, column


def chain_values():
    """The placeholders the loudness and drift scores share."""
    return dict(loudness_in=LOUDNESS_IN_SC, running_sum_chain=running_sum_chain_sc("in"),
                amplitude_chain=amplitude_chain_sc("in"))


def score_code(bench):
    return scores.code("loudness", seconds=SECONDS, osc=scores.sc_path(bench.work / "loudness.osc"),
                       **chain_values())


def errors(data, skip):
    """data: frames x [in, ltf, chain, amp]; errors in N after `skip` frames (the history the
    reference does not have at the start of a capture). Also returns the reference."""
    want = reference.equations_1_and_2(data[:, 0], LTF_N)[skip:]
    inside = (want > MAPPING["loForceN"]) & (want < MAPPING["hiForceN"])
    out = {}
    for name, col in CHAINS:
        e = np.abs(data[skip:, col].astype(np.float64) - want)
        out[name] = {"max_n": float(e.max()), "rms_n": float(np.sqrt(np.mean(e ** 2))),
                     "max_n_inside_clip": float(e[inside].max()) if inside.any() else 0.0}
    return out, want


def analyse(bench):
    """(results, the rendered frames, the reference) of the loudness render."""
    data, rate = readers.read_wav(bench.work / "loudness.wav")
    assert rate == SR
    errs, want = errors(data, 0)
    return {"errors": errs, "seconds": len(data) / SR}, data, want
