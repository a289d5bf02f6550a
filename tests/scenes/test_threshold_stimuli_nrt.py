"""What FrictionThreshold's intervals play (FrictionThresholdStimuli), rendered in NRT on simulated
devices whose hands move at a steady speed: the grating's period against the puck's position is
the reference's, plus the level in the target; the asynchrony experiment's sound starts the
device's audio delay plus the level (ms) after it is switched on."""
import numpy as np
import pytest

from kfharness import nrt, paths, profile
from kfstudy import readers

RATE = 48000
ON_S = 0.5  # the asynchrony synths' trial starts


def _period_mm(path):
    """Twice the median travel between the grating's switches (duty 0.5), from a lockstep
    recording: the frames' audio times against the reports' (the same clock in NRT)."""
    session = readers.Session(path)
    count_mm = float(session.header["countMm"])
    x_mm = np.interp(session.frames[:, 1], session.reports[:, 0], np.cumsum(session.reports[:, 2]) * count_mm)
    high = session.frames[:, 2] > 0.22
    switches = np.flatnonzero(np.diff(high.astype(int)))
    travel = np.abs(np.diff(x_mm[switches]))
    assert len(travel) >= 10, len(travel)
    return 2 * float(np.median(travel))


def test_grating_period_and_sound_delay_follow_the_level():
    rec = [paths.work_dir() / f"stimuli-grating-{i}.kfs" for i in (0, 1)]
    data, log = nrt.score_and_render("threshold-stimuli", f"""
        var grating = (periodMm: 2, duty: 0.5, loForceN: 0.14, hiForceN: 0.3);
        var sound = (samplesPerMm: 500, amp: 0.5);
        var defs = [FrictionThresholdStimuli.synthDef(\\grating, 0, grating),
            FrictionThresholdStimuli.synthDef(\\grating, 1, grating),
            FrictionThresholdStimuli.synthDef(\\asynchrony, 2, sound),
            FrictionThresholdStimuli.synthDef(\\asynchrony, 3, sound)];
        var hand = FrictionHand.speeds([[40, 3]]);
        score = Score(FrictionPilot.loadSignalMsgs(0).collect {{ |m| [0.0, m] }} ++ [
            [0.0] ++ defs.collect {{ |d| ['/d_recv', d.asBytes] }},
            [0.0] ++ (0..3).collect {{ |i| ['/cmd', \\kfOpenSim, i] ++ hand.asCommandArgs }},
            [0.0, ['/cmd', \\kfRecord, 0, "{rec[0]}"], ['/cmd', \\kfRecord, 1, "{rec[1]}"]],
            [0.1, Synth.basicNew(defs[0].name, nil, 1000).newMsg(nil, [\\level1, 0, \\intervalS, 9, \\trial, 1]),
                Synth.basicNew(defs[1].name, nil, 1001).newMsg(nil, [\\level1, 1, \\intervalS, 9, \\trial, 1]),
                Synth.basicNew(defs[2].name, nil, 1002).newMsg(nil, [\\level1, 0, \\out, 0, \\bufnum, 0]),
                Synth.basicNew(defs[3].name, nil, 1003).newMsg(nil, [\\level1, 10, \\out, 2, \\bufnum, 0])],
            [{ON_S}, ['/n_set', 1002, \\trial, 1], ['/n_set', 1003, \\trial, 1]],
            [2.5, ['/c_set', 0, 0]]]);
    """, channels=4)
    assert "FAILURE" not in log, log[-2000:]
    # The grating: 2 mm in the reference, 2 + 1 mm in the target; the switches fall on 1 ms frames
    # (0.04 mm at 40 mm/s) and the median is over tens of half periods: within 5 %.
    assert abs(_period_mm(rec[0]) / 2 - 1) < 0.05
    assert abs(_period_mm(rec[1]) / 3 - 1) < 0.05
    # The sound: silent until switched on, then delayed by the paper's 1 ms (a slot index has the
    # paper's audioDelay) plus the level. active is a control-rate signal: the sound's amplitude
    # ramps from 0 over the block of the bundle (SC interpolates a control into an audio product),
    # whose first sample is still 0, so the sound starts delay + 1 samples after that block begins; DelayL
    # delays by a whole number of samples here. The level's 10 ms is exactly 480 samples.
    on = nrt.bundle_start_sample(ON_S)
    first = [int(np.flatnonzero(np.abs(data[:, channel]) > 1e-7)[0]) for channel in (0, 2)]
    assert first[0] == on + round(0.001 * RATE) + 1, (first, on)
    assert first[1] - first[0] == round(0.010 * RATE), first
    for channel, start in zip((0, 2), first):
        assert np.abs(data[start:start + 4800, channel]).max() > 0.1, "the pilot's sound plays"


@pytest.mark.parametrize("rate", [44100, 48000, 192000])
def test_the_server_times_a_trials_intervals(rate):
    """A trial's two intervals come from its one \\trial (FrictionThresholdStimuli.trialControls):
    intervalS each, gapS after the first, \\level1 in the first and \\level2 in the second; a
    \\trial sent while one plays starts the next at once, whole, and never doubles the force. At
    the lowest, the usual and the highest sample rate a study may run at (its timer counts seconds
    at control rate, whose block is 1.45 to 0.33 ms long)."""
    rec = paths.work_dir() / f"stimuli-trial-{rate}.kfs"
    # The second inside the first trial's second interval (1.15 to 1.65 s), the third in the
    # second's gap (1.9 to 2.05 s).
    starts_s = [0.5, 1.4, 1.95]
    _, log = nrt.score_and_render("threshold-trial", f"""
        var def = FrictionThresholdStimuli.synthDef(\\force, 0, (baseForceN: 0.3));
        score = Score([
            [0.0, ['/d_recv', def.asBytes], ['/cmd', \\kfOpenSim, 0] ++ FrictionHand.speeds([[40, 3]]).asCommandArgs,
                ['/cmd', \\kfRecord, 0, "{rec}"]],
            [0.1, Synth.basicNew(def.name, nil, 1000).newMsg(nil, [\\intervalS, 0.5, \\gapS, 0.15])],
            [{starts_s[0]}, ['/n_set', 1000, \\level1, 0, \\level2, 0.2, \\trial, 1]],
            [{starts_s[1]}, ['/n_set', 1000, \\level1, 0.1, \\level2, 0.1, \\trial, 1]],
            [{starts_s[2]}, ['/n_set', 1000, \\level1, 0.2, \\level2, 0.05, \\trial, 1]],
            [3.5, ['/c_set', 0, 0]]]);
    """, sample_rate=rate)
    assert "FAILURE" not in log, log[-2000:]
    frames = readers.Session(rec).frames
    audio_s, commanded_n = frames[:, 1], frames[:, 3]
    # What each span asks (s from, s to, N): the first trial's reference, gap, target; the second
    # trial from its start (the first's target cut short), its gap; the third from its start, whole.
    # Between intervals 0 N is asked, the simulated device's minimum (the paper's) commanded.
    off_n = profile.device()["minForceN"]
    first, second, third = (nrt.bundle_start_sample(t, rate) / rate for t in starts_s)
    spans = [(first, first + 0.5, 0.3), (first + 0.5, first + 0.65, off_n), (first + 0.65, second, 0.5),
             (second, second + 0.5, 0.4), (second + 0.5, third, off_n),
             (third, third + 0.5, 0.5), (third + 0.5, third + 0.65, off_n), (third + 0.65, third + 1.15, 0.35),
             (third + 1.15, 3.5, off_n)]
    # The edges fall on control blocks (up to 1.45 ms) and a frame is the mean of 1 ms: 3 ms from
    # each edge every frame (one a ms) asks the span's force.
    for lo_s, hi_s, want_n in spans:
        inside = commanded_n[(audio_s > lo_s + 0.003) & (audio_s < hi_s - 0.003)]
        assert len(inside) >= (hi_s - lo_s - 0.006) * 1000 - 1, (lo_s, hi_s, len(inside))
        assert np.all(np.abs(inside - want_n) < 1e-6), (lo_s, hi_s, want_n, np.unique(inside))
    assert commanded_n.max() < 0.5 + 1e-6
