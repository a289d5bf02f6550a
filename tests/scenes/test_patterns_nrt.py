"""FrictionPattern rendered by scsynth -N on the simulated device (a FrictionHand moving the puck
out fast and back slowly), every pattern against its definition recomputed in numpy from the
position FrictionMouseIn gave it (kfharness.patterns)."""
import numpy as np
import pytest

from kfharness import nrt, patterns

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


def render(rate, seconds):
    outs = ", ".join(code for _, code, _ in KINDS)
    data, log = nrt.score_and_render(f"patterns{rate}", f"""
        var dev = FrictionDevice.sim(nil, 0, FrictionHand.path([[0, 0], [0.25, 40], [0.35, 40], [{seconds}, 20]]));
        var def = SynthDef(\\patterns, {{
            var x = FrictionMouseIn.ar(0)[0], h = sin(x * 0.5), fast = Sweep.ar(0, 300);
            Out.ar(0, [x, h, {outs}, FrictionPattern.grating(fast, 0.2, 0.5, 0.02),
                FrictionPattern.grating(fast, 0.2, 0.5, 0.02, antialias: 0)])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\patterns, nil, 1000).newMsg],
            [{seconds}, dev.closeMsg],
            [{seconds} + 0.01, ['/c_set', 0, 0]]]);
    """, sample_rate=rate, channels=4 + len(KINDS))
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


def test_a_fine_grating_moved_fast_has_no_alias_in_its_frames():
    # 300 mm/s over 0.2 mm: 1500 Hz, above the frames' 500 Hz. Band-limited, the grating is its mean
    # (0.32 N) to float rounding (0.36 N * 2^-24 = 2e-8 N): stated level 1e-6 N. The raw grating's
    # frames alias (measured 0.10 N, exactly 0 with it); > 0.02 N shows this test sees an alias.
    rate = 48000
    data, _ = render(rate, 0.4)
    n = int(0.4 * rate) - 64
    on, off = (data[rate // 100:n, k].astype(np.float64) for k in (-2, -1))
    assert largest_alias_n(on, rate) < 1e-6
    assert largest_alias_n(off, rate) > 0.02
    assert abs(on.mean() - 0.32) < 1e-6
