"""SpatialBufRd rendered by scsynth -N: frequency from a position ramp, borders, bad buffers."""
import numpy as np
import soundfile

from kfharness import nrt, paths, reference

SR = 48000


def write_signal(name, frames):
    path = paths.work_dir() / f"{name}.wav"
    soundfile.write(str(path), np.asarray(frames, dtype=np.float32), SR, subtype="FLOAT")
    return path


def pilot_sine():
    """The paper's pilot signal: 240 cycles of 100 samples, amplitude 1."""
    return np.sin(2 * np.pi * np.arange(24000) / 100.0)


def test_position_ramp_over_sine_gives_speed_times_density_over_period():
    path = write_signal("sine", pilot_sine())
    speed_mm_per_s, samples_per_mm = 50.0, 500.0  # index rate 25000 /s over 100-sample cycles
    data, _ = nrt.score_and_render("ramp", f"""
        var def = SynthDef(\\ramp, {{
            Out.ar(0, SpatialBufRd.ar(1, 0, Sweep.ar(0, {speed_mm_per_s}), {samples_per_mm}, 0, 4))
        }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\ramp, nil, 1000).newMsg],
            [0.8, ['/c_set', 0, 0]]]);
    """)
    x = data[:, 0]
    expected_hz = speed_mm_per_s * samples_per_mm / 100.0
    assert abs(reference.zero_crossing_frequency(x, SR) / expected_hz - 1) < 1e-4
    # Per sample against the continuous sine the buffer samples (cubic error only).
    t = (np.arange(len(x)) + 1) / SR  # Sweep has advanced one sample at its first output
    truth = np.sin(2 * np.pi * t * speed_mm_per_s * samples_per_mm / 100.0)
    inside = np.arange(len(x)) >= 2  # from index 1 on, all four cubic taps are inside the signal
    assert np.max(np.abs(x - truth)[inside]) < 2e-4


def test_silence_before_and_after_the_signal_and_fades_at_the_borders():
    path = write_signal("ones", np.ones(1000))
    # Position -1 mm .. +11 mm over 1.2 s with 100 samples per mm: the signal spans 0 .. 10 mm.
    data, _ = nrt.score_and_render("borders", f"""
        var def = SynthDef(\\borders, {{
            Out.ar(0, SpatialBufRd.ar(1, 0, Sweep.ar(0, 10) - 1, 100, 0, 4))
        }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\borders, nil, 1000).newMsg],
            [1.2, ['/c_set', 0, 0]]]);
    """)
    x = data[:, 0].astype(np.float64)
    position = (np.arange(len(x)) + 1) / SR * 10.0 - 1.0
    index = position * 100
    margin = 0.01  # Sweep's float accumulation over a second
    assert np.all(x[index <= -1.0 - margin] == 0.0)
    assert np.all(x[index >= 1000.0 + margin] == 0.0)
    inside = (index >= 1.0) & (index <= 997.0)
    assert np.allclose(x[inside], 1.0, atol=1e-6)
    # The fade-in is the cubic kernel over (0, 0, 1, 1): from 0 to 1 with its small overshoot.
    fade = (index > -1.0) & (index < 1.0)
    assert x[fade][0] < 0.05 and x[fade][-1] > 0.95
    assert np.all((x[fade] > -0.1) & (x[fade] < 1.1))


def test_multichannel_buffer():
    frames = np.stack([pilot_sine(), -0.5 * pilot_sine()], axis=1)
    path = paths.work_dir() / "stereo.wav"
    soundfile.write(str(path), frames.astype(np.float32), SR, subtype="FLOAT")
    data, _ = nrt.score_and_render("stereo", f"""
        var def = SynthDef(\\stereo, {{
            Out.ar(0, SpatialBufRd.ar(2, 0, Sweep.ar(0, 20), 500))
        }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\stereo, nil, 1000).newMsg],
            [0.5, ['/c_set', 0, 0]]]);
    """, channels=2)
    assert np.max(np.abs(data[:, 0])) > 0.99
    assert np.allclose(data[:, 1], -0.5 * data[:, 0], atol=1e-6)


def test_missing_freed_and_mismatched_buffers_give_silence_and_one_message_each():
    path = write_signal("sine2", pilot_sine())
    stereo = paths.work_dir() / "stereo2.wav"
    soundfile.write(str(stereo), np.stack([pilot_sine()] * 2, axis=1).astype(np.float32), SR, subtype="FLOAT")
    data, log = nrt.score_and_render("badbufs", f"""
        var def = SynthDef(\\bad, {{ |out, buf|
            Out.ar(out, SpatialBufRd.ar(1, buf, Sweep.ar(0, 10), 500))
        }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/b_allocRead', 1, "{stereo}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\bad, nil, 1000).newMsg(nil, [\\out, 0, \\buf, 0])],
            [0.0, Synth.basicNew(\\bad, nil, 1001).newMsg(nil, [\\out, 1, \\buf, 7])],
            [0.0, Synth.basicNew(\\bad, nil, 1002).newMsg(nil, [\\out, 2, \\buf, 1])],
            [0.2, ['/b_free', 0]],
            [0.4, ['/b_allocRead', 0, "{path}"]],
            [0.6, ['/c_set', 0, 0]]]);
    """, channels=3)
    t = np.arange(len(data)) / SR
    assert np.all(np.isfinite(data))
    assert np.max(np.abs(data[t < 0.19, 0])) > 0.9, "plays before the free"
    assert np.all(data[(t > 0.21) & (t < 0.39), 0] == 0.0), "silent while freed"
    assert np.max(np.abs(data[t > 0.41, 0])) > 0.9, "plays again once reallocated"
    assert np.all(data[:, 1] == 0.0), "a buffer never allocated is silent"
    assert np.all(data[:, 2] == 0.0), "a channel-count mismatch is silent"
    assert log.count("SpatialBufRd: buffer 7 is not allocated") == 1, log
    assert log.count("SpatialBufRd: buffer 0 is not allocated") == 1, log
    assert log.count("SpatialBufRd: buffer 1 has 2 channels but numChannels is 1") == 1, log


def test_nan_and_inf_positions_give_silence():
    path = write_signal("sine3", pilot_sine())
    data, _ = nrt.score_and_render("nanpos", f"""
        var def = SynthDef(\\nanpos, {{
            var infinite = DC.ar(1e30) * 1e30, nan = infinite - infinite;
            // samplesPerMm through a control: the class rejects a literal inf.
            Out.ar(0, [SpatialBufRd.ar(1, 0, nan, 500), SpatialBufRd.ar(1, 0, infinite, 500),
                SpatialBufRd.ar(1, 0, DC.ar(1), \\spm.kr(inf)), nan, infinite])
        }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\nanpos, nil, 1000).newMsg],
            [0.1, ['/c_set', 0, 0]]]);
    """, channels=5)
    assert np.all(np.isnan(data[:, 3])) and np.all(np.isinf(data[:, 4])), "the inputs really were NaN and Inf"
    assert np.all(data[:, :3] == 0.0)
