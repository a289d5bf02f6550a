"""FrictionPattern rendered by scsynth -N on the simulated device (a FrictionHand moving the puck
out fast and back slowly), every pattern against its definition recomputed in numpy from the
position FrictionMouseIn gave it (kfharness.patterns)."""
import numpy as np
import pytest

from kfharness import nrt, patterns, sclang_session

LO, HI = 0.14, 0.5
# name, FrictionPattern code on x (and h, a height signal), reference level from (x, h, rate)
KINDS = [
    ("grating", "FrictionPattern.grating(x, 0.8, 0.4, 0.1)", lambda x, h, r: patterns.grating(x, r, 0.8, 0.4, 0.1)),
    ("grating raw", "FrictionPattern.grating(x, 0.8, 0.4, 0.1, antialias: 0)",
     lambda x, h, r: patterns.grating(x, r, 0.8, 0.4, 0.1, antialias=False)),
    ("bumps", "FrictionPattern.bumps(x, 4, 2)", lambda x, h, r: patterns.bumps(x, r, 4, 2)),
    ("valleys", "FrictionPattern.bumps(x, 5, 3, 1)", lambda x, h, r: patterns.bumps(x, r, 5, 3, valleys=True)),
    ("detents", "FrictionPattern.detents(x, 3, 0.6)", lambda x, h, r: patterns.detents(x, r, 3, 0.6)),
    ("texture", "FrictionPattern.texture(x, 0.5, 3, 11)", lambda x, h, r: patterns.texture(x, r, 0.5, 3, 11)),
    ("viscous", "FrictionPattern.viscous(x, 150)", lambda x, h, r: patterns.viscous(x, r, 150)),
    ("stick-slip", "FrictionPattern.stickSlip(x, 30, 10)", lambda x, h, r: patterns.stick_slip(x, r, 30, 10)),
    ("slope of a height", "FrictionPattern.slope(x, h, 0.5)", lambda x, h, r: patterns.slope(x, h, r, 0.5)),
]


# Channels after the kinds: a fine grating on position ramps (Sweep), with and without
# anti-aliasing; a viscous pattern on a control-rate ramp; a grating whose period changes while moving.
EXTRA = [
    ("fast", "FrictionPattern.grating(Sweep.ar(0, 300), 0.2, 0.5, 0.02)"),
    ("fast raw", "FrictionPattern.grating(Sweep.ar(0, 300), 0.2, 0.5, 0.02, antialias: 0)"),
    # Made for a device framing force at 8 kHz (a board of protocol 2.1).
    ("fast 8 kHz", "FrictionPattern.grating(Sweep.ar(0, 300), 0.2, 0.5, 0.02, forceFramePeriod: 0.000125)"),
    ("36 mm/s", "FrictionPattern.grating(Sweep.ar(0, 36), 0.2, 0.5, 0.02)"),
    ("60 mm/s duty 0.3", "FrictionPattern.grating(Sweep.ar(0, 60), 0.2, 0.3, 0.02)"),
    # With the force range by name, as LoudnessToFriction names it (loForce, hiForce).
    ("viscous kr", "FrictionPattern.viscous(Sweep.kr(0, 40), 100, loForce: 0.1, hiForce: 0.6)"),
    # 10 mm/s from 1.237 mm; the period 1 -> 0.37 mm in the block after 0.2 s (x ~ 3.25 mm: cycle
    # 0.25, high in both periods with the phase kept, low (cycle 0.78) without).
    ("period change", "FrictionPattern.grating(Sweep.ar(0, 10) + 1.237, Select.kr(Sweep.kr(0, 1) > 0.2, [1, 0.37]), "
     "0.5, 0.05)"),
    ("period fixed", "FrictionPattern.grating(Sweep.ar(0, 10) + 1.237, 1, 0.5, 0.05)"),
]


def column(data, name):
    return data[:, 2 + len(KINDS) + [n for n, _ in EXTRA].index(name)].astype(np.float64)


def render(rate, seconds):
    outs = ", ".join(code for _, code, _ in KINDS)
    extra = ", ".join(code for _, code in EXTRA)
    data, log = nrt.score_and_render(f"patterns{rate}", f"""
        var dev = FrictionDevice.describeSim(0, FrictionHand.path([[0, 0], [0.25, 40], [0.35, 40], [{seconds}, 20]]));
        var def = SynthDef(\\patterns, {{
            var x = FrictionMouseIn.ar(0)[0], h = sin(x * 0.5);
            Out.ar(0, [x, h, {outs}, {extra}])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\patterns, nil, 1000).newMsg],
            [{seconds}, dev.closeMsg],
            [{seconds} + 0.01, ['/c_set', 0, 0]]]);
    """, sample_rate=rate, channels=2 + len(KINDS) + len(EXTRA))
    return data, log


@pytest.mark.parametrize("rate", [44100, 192000])
def test_every_pattern_on_the_simulated_device_is_its_definition(rate):
    seconds = 1.2
    data, log = render(rate, seconds)
    n = int(seconds * rate) - 64  # the synth's last block, before it is freed
    x, h = data[:n, 0], data[:n, 1]
    speed = np.abs(np.diff(x)) * rate
    assert x.max() > 30 and speed.max() > 150 and (np.diff(x) < 0).any(), "out fast and back"
    for i, (name, _, reference) in enumerate(KINDS):
        force = data[:n, 2 + i].astype(np.float64)
        want = LO + (HI - LO) * reference(x, h, rate)
        err = np.abs(force - want)
        # float32 output of a double computation: 0.5 N * 2^-24 = 3e-8 N; the positions, heights and
        # parameters are the same float32 values in both (measured worst: 1.5e-8 N over every
        # pattern; 8e-5 N before the reference took the parameters as floats), hence 1e-6 N.
        assert err.max() < 1e-6, f"{name}: worst {err.max()} N at sample {err.argmax()} (x {x[err.argmax()]})"
        assert force.max() - force.min() > 0.05, f"{name} moved the force"
    assert "FrictionPattern" not in log, log


def largest_alias_n(force, rate):
    """The largest spectral amplitude (N, Hann window, DC excluded) of the force's 1 ms means: the
    frames the device would get."""
    n = patterns.frame_samples(rate)
    frames = force[:len(force) // n * n].reshape(-1, n).mean(axis=1)
    w = np.hanning(len(frames))
    return (2 * np.abs(np.fft.rfft((frames - frames.mean()) * w)) / w.sum())[3:].max()


def frame_means(force, rate):
    n = patterns.frame_samples(rate)
    return force[:len(force) // n * n].reshape(-1, n).mean(axis=1)


def amplitude_at(frames, frequency_hz):
    """Amplitude (N) at one frequency of 1 kHz frames: a DFT there under a 4-term Blackman-Harris
    window (sidelobes below -92 dB)."""
    i = np.arange(len(frames))
    p = 2 * np.pi * i / len(frames)
    w = 0.35875 - 0.48829 * np.cos(p) + 0.14128 * np.cos(2 * p) - 0.01168 * np.cos(3 * p)
    v = frames - frames.mean()
    return 2 * abs(np.sum(v * w * np.exp(-2j * np.pi * frequency_hz * i / 1000))) / w.sum()


_rendered = {}


def render48k():
    if not _rendered:
        _rendered["data"] = render(48000, 0.4)[0]
    return _rendered["data"]


def test_a_fine_grating_moved_fast_has_no_alias_in_its_frames():
    # 300 mm/s over 0.2 mm: 1500 Hz, above the frames' 500 Hz. Band-limited, the grating is its mean
    # (0.32 N) to float rounding (0.36 N * 2^-24 = 2e-8 N): stated level 1e-6 N. The raw grating's
    # frames alias (measured 0.10 N, exactly 0 with it); > 0.02 N shows this test sees an alias.
    rate = 48000
    data = render48k()
    n = int(0.4 * rate) - 64
    on, off = (column(data, name)[rate // 100:n] for name in ("fast", "fast raw"))
    assert largest_alias_n(on, rate) < 1e-6
    assert largest_alias_n(off, rate) > 0.02
    assert abs(on.mean() - 0.32) < 1e-6
    # The harmonics of a sharp grating (0.02 mm edges) fold when only the fundamental is faded:
    # 36 mm/s, 540 Hz -> 460 Hz (was 0.0195 N); 60 mm/s duty 0.3, 600 Hz -> 400 Hz (was 0.021 N).
    # Each harmonic band-limited on its own frequency: nothing there but float rounding and the
    # window's leakage from the lines kept (>= 80 Hz away: < 1e-6 N); stated level 1e-5 N.
    for name, folded in (("36 mm/s", 460.0), ("60 mm/s duty 0.3", 400.0)):
        frames = frame_means(column(data, name)[rate // 100:n], rate)
        assert amplitude_at(frames, folded) < 1e-5, name


def test_a_fine_grating_made_for_8_khz_frames_keeps_its_line_there():
    # The same 1500 Hz grating made for 125 us frames: its band limit is 4 kHz there, so its line is
    # in the device's 8 kHz frames (6 samples at 48 kHz), 0.095 N by the pattern's own spline taper
    # (dsp test "anti-aliasing follows the force rate"); > 0.05 N, where the 1 ms pattern has none.
    rate = 48000
    data = render48k()
    n = int(0.4 * rate) - 64
    fast8k, fast = (column(data, name)[rate // 100:n] for name in ("fast 8 kHz", "fast"))
    frames8k = fast8k[:len(fast8k) // 6 * 6].reshape(-1, 6).mean(axis=1)
    i = np.arange(len(frames8k))
    p = 2 * np.pi * i / len(frames8k)
    w = 0.35875 - 0.48829 * np.cos(p) + 0.14128 * np.cos(2 * p) - 0.01168 * np.cos(3 * p)
    line_n = 2 * abs(np.sum((frames8k - frames8k.mean()) * w * np.exp(-2j * np.pi * 1500 * i / 8000))) / w.sum()
    assert line_n > 0.05, line_n
    assert largest_alias_n(fast, rate) < 1e-6


def test_control_rate_positions_and_period_changes_while_moving():
    rate = 48000
    data = render48k()
    n = int(0.4 * rate) - 64
    # A control-rate ramp at 40 mm/s, interpolated across each block: viscous (full at 100 mm/s,
    # loForce 0.1 N, hiForce 0.6 N) is 0.1 + 0.5 * 0.4 = 0.3 N throughout. Float positions up to
    # 16 mm (2e-6 mm steps) move the speed over a 1 ms frame by 4e-3 mm/s: 2e-5 N; stated 1e-4 N.
    # Held per block (64 samples against 48-sample frames), the speed read 0..53 mm/s: a buzz at
    # block rate (measured 0.144 N off).
    viscous = column(data, "viscous kr")[rate // 50:n]
    assert np.abs(viscous - 0.3).max() < 1e-4
    # The period 1 -> 0.37 mm while moving at 10 mm/s: no step at the change beyond the largest the
    # moving pattern makes by itself (the same grating with a fixed period, over the whole run).
    changed, fixed = column(data, "period change")[:n], column(data, "period fixed")[:n]
    own = np.abs(np.diff(fixed[rate // 100:])).max()
    at = int(0.2 * rate)
    assert np.abs(np.diff(changed[at - 128:at + 256])).max() <= own
    assert changed[at - 128] > 0.45 and changed[at + 256] > 0.45, "high before and after: the phase kept"


def test_bumps2d_under_the_hands_circle_is_its_definition():
    # The simulated hand's circle (r 15 mm about (1, 1) at 60 mm/s: 1.57 s a turn) over a grid of
    # bumps (4 by 3 mm, 2 mm wide), against kfharness.patterns.bumps2d at the positions
    # FrictionMouseIn gave; same float tolerance as the 1D kinds (measured here: 1.5e-8 N at worst).
    rate, seconds = 48000, 1.2
    data, log = nrt.score_and_render("patterns2d", f"""
        var dev = FrictionDevice.describeSim(0, FrictionHand.circle(15, 60, 1, 1, 1));
        var def = SynthDef(\\patterns2d, {{
            var m = FrictionMouseIn.ar(0);
            Out.ar(0, [m[0], m[1], FrictionPattern.bumps2D(m[0], m[1], 4, 3, 2)])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\patterns2d, nil, 1000).newMsg],
            [{seconds}, dev.closeMsg],
            [{seconds} + 0.01, ['/c_set', 0, 0]]]);
    """, sample_rate=rate, channels=3)
    n = int(seconds * rate) - 64
    x, y, force = (data[:n, i].astype(np.float64) for i in range(3))
    assert np.ptp(x) > 3 and np.ptp(y) > 3, "the puck goes round in x and y"
    want = LO + (HI - LO) * patterns.bumps2d(x, y, rate, 4, 3, 2)
    err = np.abs(force - want)
    assert err.max() < 1e-6, f"worst {err.max()} N at sample {err.argmax()}"
    # Descents are free but for the band limit's smoothing at 60 mm/s (the series' kernel tails).
    assert force.max() - force.min() > 0.05 and (force < LO + 1e-3).mean() > 0.2, "climbs and descents"
    assert "FrictionPattern" not in log, log


def test_texture2d_along_a_line_at_an_angle_is_its_definition():
    # The simulated hand's line at 30 degrees (50 mm at 250 mm/s from (1, -2)) over a 2D texture of
    # 0.5..3 cycles/mm: waves up to 750 Hz along the line, so some fade, some are gone, some kept;
    # band-limited and raw, against kfharness.patterns.texture2d at the positions FrictionMouseIn
    # gave; the same float tolerance as the 1D kinds (1e-6 N).
    rate, seconds = 48000, 0.4
    data, log = nrt.score_and_render("patterns-texture2d", f"""
        var dev = FrictionDevice.describeSim(0, FrictionHand.line(30, 50, 250, 1, -2));
        var def = SynthDef(\\texture2d, {{
            var m = FrictionMouseIn.ar(0);
            Out.ar(0, [m[0], m[1], FrictionPattern.texture2D(m[0], m[1], 0.5, 3, 11),
                FrictionPattern.texture2D(m[0], m[1], 0.5, 3, 11, antialias: 0)])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\texture2d, nil, 1000).newMsg],
            [{seconds}, dev.closeMsg],
            [{seconds} + 0.01, ['/c_set', 0, 0]]]);
    """, sample_rate=rate, channels=4)
    n = int(seconds * rate) - 64
    x, y, on, off = (data[:n, i].astype(np.float64) for i in range(4))
    assert np.ptp(x) > 10 and np.ptp(y) > 5, "the puck goes along the line in x and y"
    assert (np.hypot(np.diff(x), np.diff(y)) * rate).max() > 150, "fast enough to fade waves"
    for force, antialias in ((on, True), (off, False)):
        want = LO + (HI - LO) * patterns.texture2d(x, y, rate, 0.5, 3, 11, antialias=antialias)
        err = np.abs(force - want)
        assert err.max() < 1e-6, f"antialias {antialias}: worst {err.max()} N at sample {err.argmax()}"
        assert np.ptp(force) > 0.05
    assert np.abs(on - off).max() > 0.01, "the band limit is what is tested"
    assert "FrictionPattern" not in log, log


def test_literal_arguments_are_checked_when_the_synthdef_is_built():
    out = sclang_session.run("""
        var errors = List.new;
        SynthDef(\\good, { Out.ar(0, FrictionPattern.texture2D(DC.ar(0), DC.ar(0), 0.5, 3, 1)) }).add;
        [
            { FrictionPattern.texture2D(DC.ar(0)) },
            { FrictionPattern.texture2D(DC.ar(0), DC.ar(0), 0) },
            { FrictionPattern.texture2D(DC.ar(0), DC.ar(0), 0.5, inf) },
            { FrictionPattern.grating(DC.ar(0), forceFramePeriod: 0) },
            { FrictionPattern.viscous(DC.ar(0), forceFramePeriod: DC.kr(0.001)) }
        ].do { |f| try { SynthDef(\\bad, f).add } { |e| errors.add(e.errorString) } };
        errors.do(_.postln);
    """)
    assert "y is required" in out
    assert "lo and hi must be finite numbers > 0 (cycles/mm), got 0 and 3" in out
    assert "lo and hi must be finite numbers > 0 (cycles/mm), got 0.5 and inf" in out
    assert "forceFramePeriod must be a number of seconds, 0.0001 to 0.1 (the device's forceFramePeriodS), got 0" in out
    assert "forceFramePeriodS), got an OutputProxy" in out  # a UGen: it is fixed at init
    assert out.count("ERROR") == 5, out
