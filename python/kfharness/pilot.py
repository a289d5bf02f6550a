"""The pilot interaction of the paper (section 3, Table 1) rendered in NRT with FrictionPilot on
a simulated device, and the measurements the main job and the scene tests make on it.

One copy of the shared logic: scripts/pilot/main_job.py and tests/scenes/test_pilot_claims.py
both use this module.
"""
from dataclasses import dataclass, field

import numpy as np

from . import nrt, profile, reference
from kfstudy import readers

_PILOT = profile.pilot()
_DEVICE = profile.device()

# Table 1 of the paper, as printed (frequencies rounded there).
TABLE1 = {
    "mapping1": dict(samples_per_mm=_PILOT["mapping1SamplesPerMm"], cycle_mm=0.025, width_mm=6.0, lo_hz=104.0, hi_hz=13360.0),
    "mapping2": dict(samples_per_mm=_PILOT["mapping2SamplesPerMm"], cycle_mm=0.2, width_mm=48.0, lo_hz=13.0, hi_hz=1670.0),
    "mapping3": dict(samples_per_mm=_PILOT["mapping3SamplesPerMm"], cycle_mm=12.5, width_mm=3000.0, lo_hz=0.2, hi_hz=26.7),
}
SIGNAL_FRAMES = _PILOT["signalFrames"]
CYCLE_FRAMES = _PILOT["cycleFrames"]
MIN_FORCE_N = _DEVICE["minForceN"]              # magnet off (the paper device)
HI_FORCE_N = profile.mapping()["hiForceN"]       # top of the paper's friction mapping
SPEED_STEP = _DEVICE["countMm"] * _DEVICE["updateRateHz"]  # 2.625 mm/s: one count per report
MAX_SPEED = profile.max_speed_mm_per_s()         # 333.375 mm/s
PAPER_SPEEDS = (2.6, 334.0)                      # as the paper rounds them
AUDIO_DELAY_S = profile.audio_delay_s()
DC_BLOCKER_HZ = 5.0                              # FrictionPilot.dcBlockerHz: LeakDC on what is heard


def dc_blocker_coef(sample_rate):
    """LeakDC's coefficient in FrictionPilot: a one-pole high-pass at DC_BLOCKER_HZ."""
    return np.exp(-2 * np.pi * DC_BLOCKER_HZ / sample_rate)

# Channels of a FrictionPilot.score render with recordBus 2.
CHANNELS = ["out_left", "out_right", "position", "speed", "audio", "delayed_audio", "force", "commanded_force"]


def frequency(speed_mm_per_s, samples_per_mm):
    """The paper's relation: one cycle is 100 samples, so f = |v| * samplesPerMm / 100."""
    return np.abs(speed_mm_per_s) * samples_per_mm / CYCLE_FRAMES


def full_scale_sine_force():
    """Equations (1)-(2) for a full-scale sine: mean |sin| = 2/pi -> -3.92 dB -> 0.453 N."""
    return float(reference.force_of_mean(2 / np.pi))


@dataclass
class Scene:
    """One condition: a mapping, friction off or on, a hand script (FrictionHand.path points)."""
    mapping: str
    friction: int
    path: list                 # [[timeS, xMm], ...]
    origin_mm: float           # where the fragment starts (the puck starts at 0, outside it)
    explored_mm: float         # how much of the fragment the script covers
    passes: list = field(default_factory=list)  # (label, t0, t1, direction) of each crossing
    duration_s: float = 0.0
    speeds_hand: bool = False  # path is FrictionHand.speeds pairs instead

    @property
    def name(self):
        return f"{self.mapping}-friction-{'on' if self.friction else 'off'}"

    @property
    def samples_per_mm(self):
        return TABLE1[self.mapping]["samples_per_mm"]


def exploration(mapping, friction):
    """Scripted explorations like Figure 2: across the fragment fast in one direction, back at a
    medium speed, then across again slowly. The puck starts 10 mm left of the fragment; the
    hand's targets overshoot so that the spring-damper hand still pushes through it at the
    highest friction. Mapping 3 (3 m) explores its first 100 mm, about 8 cycles (Figure 3)."""
    origin = 10.0
    plan = {  # explored width, right end margin, fast, medium, slow (mm/s), pause (s)
        "mapping1": (6.0, 40.0, 200.0, 80.0, 12.0, 0.4),
        "mapping2": (48.0, 40.0, 200.0, 60.0, 15.0, 0.3),
        "mapping3": (100.0, 40.0, 120.0, 50.0, 20.0, 0.3),
    }[mapping]
    width, margin, fast, medium, slow, pause = plan
    # At 0.5 N the hand (20 N/m) needs 25 mm of lag to move the puck: targets lie further out.
    left, right = -30.0, origin + width + margin
    points, t, x = [[0.0, 0.0], [0.2, 0.0]], 0.2, 0.0
    passes = []
    for label, target, speed in [("fast right", right, fast), ("medium left", left, medium), ("slow right", right, slow)]:
        t1 = t + abs(target - x) / speed
        points.append([round(t1, 4), target])
        passes.append((label, t, t1 + pause, 1 if target > x else -1, speed))
        t, x = t1 + pause, target
        points.append([round(t, 4), target])
    return Scene(mapping, friction, points, origin, width, passes, duration_s=round(t + 0.3, 3))


def score_code(scene, record_path=None):
    """sclang that leaves the scene's Score in `score` (FrictionPilot.score on a sim device)."""
    pts = ", ".join(f"[{a}, {b}]" for a, b in scene.path)
    hand = f"FrictionHand.{'speeds' if scene.speeds_hand else 'path'}([{pts}])"
    rec = f'"{record_path}"' if record_path else "nil"
    return f"""
        var dev = FrictionDevice.describeSim(0, {hand});
        score = FrictionPilot.score(dev, \\{scene.mapping}, {scene.friction}, {scene.duration_s},
            {scene.origin_mm}, 1, 2, {rec});
    """


def render(scene, sample_rate=48000, record_path=None):
    """Renders the scene; returns a dict of channel name -> float64 array, plus 't' (s) and 'sr'."""
    data, _ = nrt.score_and_render(f"pilot-{scene.name}-{sample_rate}", score_code(scene, record_path),
                                   sample_rate=sample_rate, channels=len(CHANNELS))
    out = {name: data[:, i].astype(np.float64) for i, name in enumerate(CHANNELS)}
    out["t"] = np.arange(len(data)) / sample_rate
    out["sr"] = sample_rate
    return out


# ---- measurements ----

def cycle_frequencies(r, samples_per_mm, origin_mm, min_speed=SPEED_STEP):
    """For every signal cycle crossed in one steady direction: (time s, measured Hz from the
    audio's rising zero crossings, the formula's Hz from the mean speed over the same cycle).
    A cycle counts when the puck moved at >= min_speed in one direction throughout it and both
    crossings lie inside the signal (not at its borders with silence)."""
    sr = r["sr"]
    c = reference.rising_crossings(r["audio"])
    index = (r["position"][np.round(c).astype(int).clip(0, len(r["position"]) - 1)] - origin_mm) * samples_per_mm
    c = c[(index > 2) & (index < SIGNAL_FRAMES - 3)]
    if len(c) < 2:
        return np.zeros((0, 3))
    a, b = c[:-1], c[1:]
    ia, ib = np.ceil(a).astype(int), np.floor(b).astype(int)
    speed = r["speed"]
    cums = np.concatenate([[0.0], np.cumsum(speed)])
    # Running min/max of speed over each cycle, to keep only one-direction cycles.
    rows = []
    for i0, i1, ca, cb in zip(ia, ib, a, b):
        if i1 <= i0:
            continue
        seg = speed[i0:i1 + 1]
        if seg.min() * seg.max() <= 0 or np.abs(seg).min() < min_speed:
            continue
        mean_speed = (cums[i1 + 1] - cums[i0]) / (i1 + 1 - i0)
        rows.append((ca / sr, sr / (cb - ca), frequency(mean_speed, samples_per_mm)))
    return np.array(rows).reshape(-1, 3)


def segment_frequency(r, t0, t1):
    """Mean frequency (Hz) from the audio's rising zero crossings between t0 and t1, and the
    mean |speed| over the same crossings' span (mm/s)."""
    sr = r["sr"]
    i0, i1 = int(t0 * sr), int(t1 * sr)
    c = reference.rising_crossings(r["audio"][i0:i1]) + i0
    if len(c) < 3:
        raise AssertionError(f"too few zero crossings in {t0}..{t1} s")
    f = sr * (len(c) - 1) / (c[-1] - c[0])
    a, b = int(np.ceil(c[0])), int(np.floor(c[-1]))
    return f, float(np.mean(np.abs(r["speed"][a:b])))


def inside(r, origin_mm, width_mm):
    return (r["position"] >= origin_mm) & (r["position"] <= origin_mm + width_mm)


def outside_for(r, origin_mm, samples_per_mm, hold_s):
    """True where the puck has been outside the signal (and one sample beyond each end, where
    the cubic kernel still reaches in) for at least hold_s; False for the last block (the node
    is freed at the end of a Score)."""
    margin = 1.01 / samples_per_mm
    outside = ~inside(r, origin_mm - margin, SIGNAL_FRAMES / samples_per_mm + 2 * margin)
    n = int(hold_s * r["sr"])
    c = np.concatenate([[0], np.cumsum(~outside)])
    recent_inside = c[n:] - c[:-n]  # inside samples among the n up to each sample
    held = np.zeros_like(outside)
    held[n - 1:] = recent_inside == 0
    held[-64:] = False
    return held


def crossing_times(r, origin_mm, width_mm, passes):
    """For each pass (label, t0, t1, direction, target speed): the time from entering the
    fragment (explored part) to leaving it on the far side, s; NaN when it did not get across."""
    t, x = r["t"], r["position"]
    lo, hi = origin_mm, origin_mm + width_mm
    result = []
    for label, t0, t1, direction, speed in passes:
        sel = (t >= t0) & (t < t1 + 1.0)
        ts, xs = t[sel], x[sel]
        start, end = (lo, hi) if direction > 0 else (hi, lo)
        past = (lambda v, edge: v >= edge) if direction > 0 else (lambda v, edge: v <= edge)
        i_in = np.nonzero(past(xs, start))[0]
        i_out = np.nonzero(past(xs, end))[0]
        if len(i_in) == 0 or len(i_out) == 0:
            result.append((label, speed, np.nan))
        else:
            result.append((label, speed, ts[i_out[0]] - ts[i_in[0]]))
    return result


def peaks(x, min_height, min_distance):
    """Local maxima above min_height, at least min_distance samples apart (the higher wins)."""
    x = np.asarray(x)
    cand = np.nonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]) & (x[1:-1] > min_height))[0] + 1
    kept = []
    for i in cand[np.argsort(-x[cand])]:
        if all(abs(i - k) >= min_distance for k in kept):
            kept.append(i)
    return np.sort(np.array(kept, dtype=int))


def lag_samples(reference, delayed, max_lag):
    """The lag (samples) that best aligns `delayed` with `reference` (cross-correlation of the
    mean-removed signals over lags 0..max_lag)."""
    a = np.asarray(reference, dtype=np.float64) - np.mean(reference)
    b = np.asarray(delayed, dtype=np.float64) - np.mean(delayed)
    n = len(a) - max_lag
    scores = [np.dot(a[:n], b[k:k + n]) for k in range(max_lag + 1)]
    return int(np.argmax(scores))


def loudness_force(audio, sample_rate, window_s=0.001):
    """Equations (1)-(2) in numpy: the force the paper computes from an audio signal."""
    return reference.equations_1_and_2(audio, int(round(sample_rate * window_s)))


def device_force(frames, n_samples, sample_rate, min_force_n=MIN_FORCE_N):
    """The force at the device per sample from a recording's F lines: each frame's commanded
    force held from its frame time for one frame period (1 ms)."""
    force = np.full(n_samples, min_force_n)
    if len(frames) == 0:
        return force
    period = np.median(np.diff(frames[:, 0])) if len(frames) > 1 else 0.001
    for t0, _, commanded in frames:
        a, b = int(round(t0 * sample_rate)), int(round((t0 + period) * sample_rate))
        force[a:min(b, n_samples)] = commanded
    return force


def read_session_frames(path):
    """F lines of a kf-session recording: array of (frameTimeS, requestedN, commandedN)."""
    return readers.Session(path).frames[:, 1:4]
