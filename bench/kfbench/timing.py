"""Speed: one scsynth NRT render of phases, each many instances of one SynthDef, in shuffled
rounds; a KFBenchClock synth at the head writes the wall and thread-CPU time per block."""
import random

import numpy as np

from kfstudy import readers

from . import scores
from .common import LOUDNESS_IN_SC, MAPPINGS, ORIGIN, PILOT_FRAMES, SPEEDS, SR, BLOCK, amplitude_chain_sc, \
    running_sum_chain_sc

# The per-instance SynthDefs. `bus`, `spm` and `origin` are controls, so the BufRd chain really
# computes (pos - origin) * spm in float UGens, as a user's synth would.
_POS = "In.ar(\\bus.ir(100))"
_CONTROLS = f"\\spm.kr({MAPPINGS[1]}), \\origin.kr({ORIGIN:g})"
_PHASE = f"({_POS} - \\origin.kr({ORIGIN:g})) * \\spm.kr({MAPPINGS[1]})"
DEFS = {"srcpos": f"Out.ar(200, {_POS})"}
for _interp in (4, 2, 1):
    DEFS[f"spat{_interp}"] = f"Out.ar(200, SpatialBufRd.ar(1, 0, {_POS}, {_CONTROLS}, {_interp}))"
    DEFS[f"bufrd{_interp}"] = f"Out.ar(200, BufRd.ar(1, 0, {_PHASE}, 0, {_interp}))"
DEFS.update({"srcin": "Out.ar(201, In.ar(103))", "ltf": "Out.ar(201, LoudnessToFriction.ar(In.ar(103)))",
             "chain": f"Out.ar(201, {running_sum_chain_sc('In.ar(103)')})",
             "amp": f"Out.ar(201, {amplitude_chain_sc('In.ar(103)')})"})
# The device UGens, per instance, on the simulated device the score opens on slot 0 (stepped in
# lockstep with the render): FrictionMouseIn's four outputs, and FrictionOut's force (every
# instance writes to the one slot, whose frames combine them).
DEVICE_SLOT = 0
DEFS.update({"mousein": f"Out.ar(202, FrictionMouseIn.ar({DEVICE_SLOT}))",
             "fout": f"Out.ar(201, FrictionOut.ar({DEVICE_SLOT}, In.ar(103).abs))"})
PHASES = ["empty"] + list(DEFS)
SETTLE_S = 0.25  # a phase is measured from SETTLE_S after its start to TAIL_S before its end
TAIL_S = 0.05

# pair -> (A, B, the phase of A's and B's source alone)
PAIRS = {
    "SpatialBufRd/BufRd cubic": ("spat4", "bufrd4", "srcpos"),
    "SpatialBufRd/BufRd linear": ("spat2", "bufrd2", "srcpos"),
    "SpatialBufRd/BufRd none": ("spat1", "bufrd1", "srcpos"),
    "LoudnessToFriction/RunningSum chain": ("ltf", "chain", "srcin"),
    "LoudnessToFriction/Amplitude chain": ("ltf", "amp", "srcin"),
}
READERS = [("spat1", "SpatialBufRd none"), ("spat2", "SpatialBufRd linear"), ("spat4", "SpatialBufRd cubic"),
           ("bufrd1", "BufRd none"), ("bufrd2", "BufRd linear"), ("bufrd4", "BufRd cubic")]


def schedule(rounds, seed=7):
    """rounds + 1 rounds of every phase in a shuffled order; the first is a warm-up."""
    rng = random.Random(seed)
    order = []
    for _ in range(rounds + 1):
        phases = list(PHASES)
        rng.shuffle(phases)
        order += phases
    return order


def render_seconds(order, phase_s):
    return 0.6 + len(order) * phase_s


def score_code(bench, order, instances, phase_s):
    defs = ",\n".join(f"    SynthDef(\\kfb_{name}, {{ {body} }})" for name, body in DEFS.items())
    return scores.code("timing", defs=defs, order=", ".join(f"\\{p}" for p in order), instances=instances,
                       phase_s=phase_s, mappings=MAPPINGS, frames=PILOT_FRAMES, speeds=SPEEDS, origin=ORIGIN,
                       loudness_in=LOUDNESS_IN_SC, slot=DEVICE_SLOT, pilot_wav=scores.sc_path(bench.work / "pilot.wav"),
                       osc=scores.sc_path(bench.work / "timing.osc"))


def _ratio_stats(a, b, base):
    r = [(xa - xe) / (xb - xe) for xa, xb, xe in zip(a, b, base)]
    return {"median": float(np.median(r)), "min": float(np.min(r)), "max": float(np.max(r)), "all": r}


def analyse(bench, order, instances, phase_s):
    data, rate = readers.read_wav(bench.work / "timing.wav")
    assert rate == SR
    data = data.astype(np.float64)
    clocks = {"wall": data[:, 0] + data[:, 1], "cpu": data[:, 2] + data[:, 3]}
    per = {p: {"wall": [], "cpu": []} for p in PHASES}
    for p, name in enumerate(order):
        if p < len(PHASES):
            continue  # the warm-up round
        t = 0.5 + p * phase_s
        a = int(round((t + SETTLE_S) * SR)) // BLOCK * BLOCK
        b = int(round((t + phase_s - TAIL_S) * SR)) // BLOCK * BLOCK
        for clock, x in clocks.items():
            per[name][clock].append((x[b] - x[a]) / ((b - a) / SR))  # seconds of work per audio second
    res = {"instances": instances, "phase_s": phase_s, "rounds": len(order) // len(PHASES) - 1, "per_phase": per}
    res["ns"] = {clock: {name: [(x - y) * 1e9 / (instances * SR) for x, y in zip(per[name][clock], per["empty"][clock])]
                         for name in PHASES if name != "empty"} for clock in ("cpu", "wall")}
    res["ratios"] = {}
    for label, (a_name, b_name, src) in PAIRS.items():
        res["ratios"][label] = {f"{clock}-{base_label}": _ratio_stats(per[a_name][clock], per[b_name][clock],
                                                                      per[base][clock])
                                for clock in ("cpu", "wall") for base_label, base in (("empty", "empty"),
                                                                                      ("source", src))}
    # Every reader against BufRd cubic (the reference of the speed-against-error plot).
    res["vs_bufrd4"] = {}
    for name, _ in READERS:
        entry = {}
        for base_label, base in (("empty", "empty"), ("source", "srcpos")):
            stats = _ratio_stats(per[name]["cpu"], per["bufrd4"]["cpu"], per[base]["cpu"])
            stats.pop("all")
            entry[f"cpu-{base_label}"] = stats
        res["vs_bufrd4"][name] = entry
    return res
