"""LoudnessToFriction rendered by scsynth -N against equations (1) and (2) recomputed in double
(kfharness.reference)."""
import re

import numpy as np
import pytest

from kfharness import nrt, reference, sclang_session


def render_in_and_force(name, source, sample_rate, args="", seconds=0.5):
    data, log = nrt.score_and_render(name, f"""
        var def = SynthDef(\\{name}, {{
            var in = {source};
            Out.ar(0, [in, LoudnessToFriction.ar(in{args})])
        }});
        score = Score([
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\{name}, nil, 1000).newMsg],
            [{seconds}, ['/c_set', 0, 0]]]);
    """, sample_rate=sample_rate, channels=2)
    return data[:, 0], data[:, 1], log


def test_full_scale_sine_gives_0_4530_newton():
    _, force, _ = render_in_and_force("sine", "SinOsc.ar(1000)", 192000)
    plateau = force[192 * 4:]
    want = 0.14 + 0.36 * (1 + 20 * np.log10(2 / np.pi) / 30)
    assert abs(want - 0.4530) < 1e-4
    assert np.all(np.abs(plateau - want) < 3e-4)


def test_silence_gives_exactly_lo_force_and_full_scale_square_hi_force():
    _, force, _ = render_in_and_force("square", "LFPulse.ar(500, 0, 0.5, 2, -1) * (Line.ar(0, 1, 0.5) > 0.5)", 48000)
    assert np.all(force[:48 * 200] == np.float32(0.14))
    assert np.all(force[48 * 300:] == np.float32(0.5))


@pytest.mark.parametrize("sample_rate", [44100, 48000, 96000, 192000])
def test_per_sample_agreement_with_equations_1_and_2(sample_rate):
    # White noise whose level sweeps from below the -30 dB floor to above full scale.
    source = "WhiteNoise.ar(XLine.ar(0.003, 3, 0.4))"
    audio, force, _ = render_in_and_force(f"agree{sample_rate}", source, sample_rate, seconds=0.4)
    n = int(round(sample_rate * 0.001))
    want = reference.equations_1_and_2(audio, n)
    err = np.abs(force - want)
    assert np.max(err) <= 1e-6, f"worst {np.max(err)} N at sample {np.argmax(err)}"
    assert force.min() == np.float32(0.14) and force.max() == np.float32(0.5), "the sweep spans the clip range"


def test_nan_and_inf_input_never_give_nan_or_inf_force():
    source = ("Select.ar(LFPulse.ar(20, 0, 0.2) + LFPulse.ar(7, 0.5, 0.1), "
              "[WhiteNoise.ar(0.2), DC.ar(1e30) * 1e30 - (DC.ar(1e30) * 1e30), DC.ar(1e30) * 1e30])")
    audio, force, _ = render_in_and_force("nonfinite", source, 48000)
    assert np.any(np.isnan(audio)) and np.any(np.isinf(audio)), "the input really had NaN and Inf"
    assert np.all(np.isfinite(force))
    assert np.max(np.abs(force - reference.equations_1_and_2(audio, 48))) <= 1e-6


def test_window_changes_while_running_up_to_max_window():
    # The window glides from 1 to 4 ms (maxWindow 5 ms); n follows per block.
    sample_rate, block = 48000, 64
    data, _ = nrt.score_and_render("window", """
        var def = SynthDef(\\window, {
            var in = WhiteNoise.ar(0.3), window = Line.kr(0.001, 0.004, 0.3);
            Out.ar(0, [in, LoudnessToFriction.ar(in, window, maxWindow: 0.005), K2A.ar(window)])
        });
        score = Score([
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\window, nil, 1000).newMsg],
            [0.4, ['/c_set', 0, 0]]]);
    """, sample_rate=sample_rate, channels=3)
    audio, force, window = (data[:, i].astype(np.float64) for i in range(3))
    csum = np.concatenate([[0.0], np.cumsum(np.abs(audio))])
    worst = 0.0
    for start in range(0, len(audio) - block, block):
        # K2A ramps from the previous block's value; the UGen read this block's value.
        n = int(np.floor(sample_rate * np.float64(np.float32(window[start + block - 1])) + 0.5))
        for i in range(start, start + block):
            mean = (csum[i + 1] - csum[max(i + 1 - n, 0)]) / n
            want = reference.force_of_mean(mean)
            worst = max(worst, abs(force[i] - want))
    assert worst <= 1e-6


def test_control_rate_and_bad_arguments():
    out = sclang_session.run("""
        var errors = List.new;
        SynthDef(\\kr, { Out.kr(0, LoudnessToFriction.kr(SinOsc.kr(1), 0.01)) }).add;
        [
            { LoudnessToFriction.ar(DC.kr(0)) },
            { LoudnessToFriction.ar(DC.ar(0), maxWindow: \\w.kr(0.1)) },
            { LoudnessToFriction.ar(DC.ar(0), 0.2, maxWindow: 0.1) },
            { LoudnessToFriction.ar(DC.ar(0), ref: 0) },
            // Non-finite literals, and SpatialBufRd's (the server's replacements are for controls).
            { LoudnessToFriction.ar(DC.ar(0), maxWindow: inf) },
            { LoudnessToFriction.ar(DC.ar(0), 0/0) },
            { LoudnessToFriction.ar(DC.ar(0), ref: 0/0) },
            { SpatialBufRd.ar(1, 0, DC.ar(0), 0) },
            { SpatialBufRd.ar(1, 0, DC.ar(0), 100, inf) }
        ].do { |f| try { SynthDef(\\bad, f).add } { |e| errors.add(e.errorString) } };
        errors.do(_.postln);
        if(errors.size != 9) { Error("expected 9 errors, got %".format(errors.size)).throw };
    """)
    assert "in must be audio rate" in out
    assert "maxWindow is fixed at init" in out
    assert "maxWindow must be > 0 s and finite, got inf" in out
    # sclang shows 0/0 as -nan on x86-64, nan elsewhere
    assert re.search(r"window must be > 0 and <= maxWindow \(0\.05 s\), got -?nan", out)
    assert "ref must be > 0 and finite, got 0" in out and re.search(r"ref must be > 0 and finite, got -?nan", out)
    assert "samplesPerMm must be a finite number > 0, got 0" in out
    assert "origin must be finite, got inf" in out
