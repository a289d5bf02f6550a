"""Issue 13: what a user or a file sends never hangs the server or gives non-finite output,
and each problem gets one clear message (rendered by scsynth -N)."""
import numpy as np
import soundfile

from kfharness import nrt, paths, reference

SR = 48000


def ones_file(name="ones-bad", frames=2000):
    path = paths.work_dir() / f"{name}.wav"
    soundfile.write(str(path), np.ones(frames, dtype=np.float32), SR, subtype="FLOAT")
    return path


def test_bufnums_that_are_no_buffer_are_silent_with_a_message():
    path = ones_file()
    # Controls carry the values: 2^32, 1e30, inf and NaN used to be cast to an integer (buffer 0).
    data, log = nrt.score_and_render("badbufnum", f"""
        var def = SynthDef(\\badbufnum, {{ |out, buf|
            Out.ar(out, SpatialBufRd.ar(1, buf, DC.ar(5), 100))
        }});
        var nan = SynthDef(\\nanbufnum, {{ |out|
            var big = DC.kr(1e30) * 1e30;
            Out.ar(out, SpatialBufRd.ar(1, big - big, DC.ar(5), 100))
        }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, ['/d_recv', nan.asBytes]],
            [0.0, Synth.basicNew(\\badbufnum, nil, 1000).newMsg(nil, [\\out, 0, \\buf, 0])],
            [0.0, Synth.basicNew(\\badbufnum, nil, 1001).newMsg(nil, [\\out, 1, \\buf, 2 ** 32])],
            [0.0, Synth.basicNew(\\badbufnum, nil, 1002).newMsg(nil, [\\out, 2, \\buf, 1e30])],
            [0.0, Synth.basicNew(\\badbufnum, nil, 1003).newMsg(nil, [\\out, 3, \\buf, inf])],
            [0.0, Synth.basicNew(\\nanbufnum, nil, 1004).newMsg(nil, [\\out, 4])],
            [0.1, ['/c_set', 0, 0]]]);
    """, channels=5)
    assert np.allclose(data[10:, 0], 1.0), "buffer 0 itself plays"
    assert np.all(data[:, 1:] == 0.0), "a bufnum that is no buffer reads nothing"
    for shown in ["4.29497e+09", "1e+30", "inf", "nan"]:
        assert log.count(f"SpatialBufRd: bufnum {shown} is not a buffer number") == 1, log


def test_a_buffer_reallocated_300_times_in_a_second_posts_a_line_not_hundreds():
    events = []
    for i in range(300):
        t = i * 0.003
        events.append(f"[{t:.4f}, ['/b_free', 0]]")
        events.append(f"[{t + 0.0015:.4f}, ['/b_alloc', 0, 100, 1]]")
    data, log = nrt.score_and_render("storm", f"""
        var def = SynthDef(\\storm, {{ Out.ar(0, SpatialBufRd.ar(1, 0, DC.ar(0.5), 100)) }});
        score = Score([
            [0.0, ['/b_alloc', 0, 100, 1]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\storm, nil, 1000).newMsg],
            {", ".join(events)},
            [0.95, ['/c_set', 0, 0]]]);
    """)
    lines = log.count("SpatialBufRd: buffer 0 is not allocated")
    assert 1 <= lines <= 2, f"{lines} lines for 300 reallocations:\n{log[-2000:]}"


def test_nan_device_index_and_origin():
    data, log = nrt.score_and_render("nanindex", """
        var dev = FrictionDevice.describeSim(0, FrictionHand.speeds([[50, 1]]));
        var def = SynthDef(\\nanindex, {
            var big = DC.kr(1e30) * 1e30, nan = big - big, everyOtherBlock = LFPulse.kr(ControlRate.ir / 2);
            Out.ar(0, [FrictionMouseIn.ar(nan)[0], FrictionOut.ar(nan, DC.ar(1.0)),
                FrictionMouseIn.ar(0, nan)[0],
                // bad every other block: still one message each; the origin keeps its last finite value
                FrictionMouseIn.ar(Select.kr(everyOtherBlock, [0, big]))[0],
                FrictionMouseIn.ar(0, Select.kr(everyOtherBlock, [3, big]))[0], FrictionMouseIn.ar(0, 3)[0],
                FrictionOut.ar(16, DC.ar(1.0))])
        });
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\nanindex, nil, 1000).newMsg],
            [0.5, dev.closeMsg],
            [0.55, ['/c_set', 0, 0]]]);
    """, channels=7)
    assert np.all(np.isfinite(data))
    assert np.all(data[:, 0] == 0.0)
    assert np.allclose(data[:, [1, 6]], 0.14), "no device: the minimum force"
    t = np.arange(len(data)) / SR
    assert data[(t > 0.3) & (t < 0.45), 2].max() > 5, "a NaN origin counts as 0: the puck moves from 0"
    assert np.array_equal(data[:, 4], data[:, 5]), "an origin inf every other block: the last finite one is kept"
    for message in [
        "FrictionMouseIn: device nan is not a slot number 0..15; position and speed are 0.",
        "FrictionOut: device nan is not a slot number 0..15; no force is sent.",
        "FrictionMouseIn: origin nan is not finite; the last finite origin is kept (0 before the first).",
        "FrictionMouseIn: device inf is not a slot number 0..15; position and speed are 0.",
        "FrictionMouseIn: origin inf is not finite; the last finite origin is kept (0 before the first).",
        "FrictionOut: device 16 is not a slot number 0..15; no force is sent.",
    ]:
        assert log.count(message) == 1, f"{message!r} {log.count(message)} times:\n{log[-3000:]}"


def test_settings_that_would_hang_the_server_are_refused_by_name(tmp_path=paths.work_dir()):
    session = paths.work_dir() / "header-1e-300.kfs"
    session.write_text("kf-session 1 countMm=0.021 updateRateHz=125 forceFramePeriodS=1e-300\n"
                       "R 0.008 0.008 1 0 0 0\n")
    overrides = " ".join("\\countMm, 0.02," for _ in range(33))
    flood = " ".join(f"[{i * 0.002:.3f}, ['/cmd', \\kfClose, 99]]," for i in range(50))
    data, log = nrt.score_and_render("hangs", f"""
        var def = SynthDef(\\hangs, {{ Out.ar(0, [FrictionOut.ar(0, DC.ar(1.0)), FrictionOut.ar(1, DC.ar(1.0))]) }});
        score = Score([
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, ['/cmd', \\kfOpenSim, 0, -1, 0, \\forceFramePeriodS, 1e-30]],
            [0.0, ['/cmd', \\kfOpenSim, 1, -1, 0, \\updateRateHz, 1e30]],
            [0.0, ['/cmd', \\kfOpenSim, 2, -1, 0, \\stepS, 1e-12]],
            [0.0, ['/cmd', \\kfOpenSim, 3, -1, 0, \\countMm, 1e30]],
            [0.0, ['/cmd', \\kfOpenReplay, 4, "{session}"]],
            [0.0, ['/cmd', \\kfOpenSim, 5, -1, 0, {overrides} 0]],
            [0.0, ['/cmd', \\kfOpenSim, 6, 0, 4, 0, 0, \\maxForceN, 1]],
            [0.0, ['/cmd', \\kfStatus, 0/0]],
            {flood}
            [0.0, Synth.basicNew(\\hangs, nil, 1000).newMsg],
            [0.2, ['/c_set', 0, 0]]]);
    """, channels=2)
    assert np.allclose(data, 0.14), "no device opened: the minimum force"
    for message in [
        "kfOpenSim: forceFramePeriodS = 1e-30 is out of range 0.0001..0.1 s; not opened",
        "kfOpenSim: updateRateHz = 1e+30 is out of range 1..8000 Hz; not opened",
        "kfOpenSim: stepS = 1e-12 is out of range 1e-06..0.01 s; not opened",
        "kfOpenSim: countMm = 1e+30 is out of range 0.0001..10 mm; not opened",
        f"kfOpenReplay: {session}:1: header: forceFramePeriodS = 1e-300 is out of range",
        "kfOpenSim: device 5: more than 32 settings; refused\n",
        "kfOpenSim: device 6: hand script value 3 of 4: a string, not a number",
        "kfStatus: device index nan is not a slot number 0..15; refused",
    ]:
        assert message in log, f"missing {message!r}:\n{log[-3000:]}"
    assert log.count("kfClose: device index 99 is not a slot number 0..15; refused") == 1, "a flood posts one line"


def message_counts(log, prefix):
    """How many lines of the log start with prefix."""
    return sum(line.startswith(prefix) for line in log.splitlines())


# Issue 22: every ranged input of SpatialBufRd and LoudnessToFriction has a defined output for
# NaN, inf, 0, negative and too large values, and one message the first time. Values a control
# carries reach the server unchecked. Rows: (def, Synth arguments, arguments set at 0.05 s,
# message, output). The buffer holds 1..1000 and the position is 5 mm: 501 is read at origin 0 and
# 100 samples per mm, 401 at origin 1; 0 is silence (1 would be samplesPerMm 0 holding the first).
SPATIAL_ROWS = [
    ("spm", "\\spm, 0/0", "", "samplesPerMm nan is not a finite number > 0; the last good value is kept "
     "(silence before the first).", 0.0),
    ("spm", "\\spm, inf", "", "samplesPerMm inf is not a finite number > 0", 0.0),
    ("spm", "\\spm, 0", "", "samplesPerMm 0 is not a finite number > 0", 0.0),
    ("spm", "\\spm, -100", "", "samplesPerMm -100 is not a finite number > 0", 0.0),
    ("spm", "\\spm, 100", "\\spm, -1", "samplesPerMm -1 is not a finite number > 0", 501.0),
    ("flip", "\\good, 100, \\bad, -2", "", "samplesPerMm -2 is not a finite number > 0", 501.0),
    ("spm", "\\origin, inf.neg", "", "origin -inf is not finite; the last finite origin is kept (0 before the first).",
     501.0),
    ("spm", "\\origin, 1", "\\origin, 0/0", "origin nan is not finite", 401.0),
    ("flipOrigin", "\\bad, inf", "", "origin inf is not finite", 401.0),
]


def test_spatial_bufrd_bad_samples_per_mm_and_origin_keep_the_last_good_value():
    path = paths.work_dir() / "ramp-bad.wav"
    soundfile.write(str(path), np.arange(1, 1001, dtype=np.float32), SR, subtype="FLOAT")
    events = []
    for i, (name, args, later, _, _) in enumerate(SPATIAL_ROWS):
        events.append(f"[0.0, Synth.basicNew(\\{name}, nil, {1000 + i}).newMsg(nil, [\\out, {i}, {args}])]")
        if later:
            events.append(f"[0.05, ['/n_set', {1000 + i}, {later}]]")
    data, log = nrt.score_and_render("spatialbad", f"""
        // Inputs read once per block; interpolation 1 (none), so the output is the index read.
        var read = {{ |spm, origin| SpatialBufRd.ar(1, 0, DC.ar(5), spm, origin, 1) }};
        var everyOtherBlock = {{ LFPulse.kr(ControlRate.ir / 2) }};
        var defs = [
            SynthDef(\\spm, {{ |out, spm = 100, origin = 0| Out.ar(out, read.(spm, origin)) }}),
            SynthDef(\\flip, {{ |out, good, bad| Out.ar(out, read.(Select.kr(everyOtherBlock.(), [good, bad]), 0)) }}),
            SynthDef(\\flipOrigin, {{ |out, bad| Out.ar(out, read.(100, Select.kr(everyOtherBlock.(), [1, bad]))) }})
        ];
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]]]
            ++ defs.collect {{ |def| [0.0, ['/d_recv', def.asBytes]] }}
            ++ [{", ".join(events)},
            [0.1, ['/c_set', 0, 0]]]);
    """, channels=len(SPATIAL_ROWS))
    for i, (_, _, _, message, output) in enumerate(SPATIAL_ROWS):
        assert np.all(data[:, i] == output), f"row {i}: {message}: {np.unique(data[:, i])}"
        assert log.count(f"SpatialBufRd: {message}") == 1, f"row {i}: {message!r}:\n{log[-3000:]}"
    assert message_counts(log, "SpatialBufRd:") == len(SPATIAL_ROWS), log


# (def, args, messages, expected output, mapping): the output follows equations (1) and (2) with a
# window of n samples (an int), is a constant force (a float), or stays within the mapping's
# forces (None).
PAPER = {}
LOUDNESS_ROWS = [
    ("lf", "\\window, 0/0", ["window nan s is not > 0; the paper's 0.001 s used."], 48, PAPER),
    ("lf", "\\window, 0", ["window 0 s is not > 0"], 48, PAPER),
    ("lf", "\\window, -1", ["window -1 s is not > 0"], 48, PAPER),
    ("lf", "\\window, inf.neg", ["window -inf s is not > 0"], 48, PAPER),
    ("lf", "\\window, inf", ["window inf s is beyond maxWindow 0.05 s; maxWindow used."], 2400, PAPER),
    ("max01", "\\window, 1e9", ["window 1e+09 s is beyond maxWindow 0.1 s; maxWindow used."], 4800, PAPER),
    ("flip", "\\bad, -2", ["window -2 s is not > 0"], None, PAPER),  # bad every other block
    ("lf", "\\loDb, 0/0", ["loDb nan dB is not a finite level; -30 dB used."], 48, PAPER),
    ("lf", "\\hiDb, inf", ["hiDb inf dB is not a finite level; 0 dB used."], 48, PAPER),
    ("lf", "\\loForce, 0/0", ["loForce nan N is not a finite force >= 0; 0.14 N used."], 48, PAPER),
    ("lf", "\\loForce, -1", ["loForce -1 N is not a finite force >= 0; 0 N used."], 48, dict(lo_force_n=0.0)),
    ("lf", "\\hiForce, inf", ["hiForce inf N is not a finite force >= 0; 0.5 N used."], 48, PAPER),
    ("lf", "\\hiForce, -0.5", ["hiForce -0.5 N is not a finite force >= 0; 0 N used."], 48, dict(hi_force_n=0.0)),
    ("lf", "\\ref, 0", ["ref 0 is not a finite amplitude > 0; 1 used."], 48, PAPER),
    ("lf", "\\ref, -1", ["ref -1 is not a finite amplitude > 0; 1 used."], 48, PAPER),
    ("lf", "\\ref, 0/0", ["ref nan is not a finite amplitude > 0; 1 used."], 48, PAPER),
    # maxWindow is a literal the class checks: these defs have it patched in their bytes.
    ("maxnan", "", ["maxWindow nan s is not > 0; the paper's 0.05 s used."], 48, PAPER),
    ("max0", "", ["maxWindow 0 s is not > 0; the paper's 0.05 s used."], 48, PAPER),
    ("maxneg", "", ["maxWindow -1 s is not > 0; the paper's 0.05 s used."], 48, PAPER),
    # 2^22 samples (16 MiB) and 50 s (9.4 MiB) of history do not fit the render's 8 MiB of RT memory.
    ("maxinf", "", ["maxWindow inf s is beyond the history limit of 4194304 samples; 87.3813 s used.",
                    "RT memory allocation failed (16384 kB for maxWindow 87.3813 s); the output stays at the "
                    "force of silence (loForce). Raise ServerOptions.memSize."], 0.14, PAPER),
    ("max50", "\\loForce, 0.2", ["RT memory allocation failed (9375 kB for maxWindow 50 s)"], 0.2, PAPER),
]


def loudness_rows():
    """LOUDNESS_ROWS as the rendering server can give them. supernova -N hands RTAlloc plain
    malloc (in NRT mode it bypasses the real-time pool that -m sizes: supernova's
    sc_plugin_interface.cpp), so no history fails to fit there: maxinf's and max50's follow the
    mapping with the paper's window, as every other row's, without the allocation message."""
    if nrt.server() != "supernova":
        return LOUDNESS_ROWS
    rows = []
    for name, args, messages, expected, mapping in LOUDNESS_ROWS:
        if name == "maxinf":  # the history limit's message stays
            messages, expected = messages[:1], 48
        elif name == "max50":  # loForce 0.2
            messages, expected, mapping = [], 48, dict(lo_force_n=0.2)
        rows.append((name, args, messages, expected, mapping))
    return rows


def test_loudness_to_friction_bad_inputs_give_a_defined_force_and_one_message():
    rows = loudness_rows()
    synths = ",\n".join(
        f"[0.0, Synth.basicNew(\\{name}, nil, {1000 + i}).newMsg(nil, [\\out, {i + 1}, {args}])]"
        for i, (name, args, _, _, _) in enumerate(rows))
    data, log = nrt.score_and_render("loudnessbad", f"""
        // The same sound in every synth: a 50 Hz sine whose level sweeps -60..0 dB and back.
        var sound = {{ SinOsc.ar(50) * LFTri.ar(4, 3).exprange(0.001, 1) }};
        var lf = {{ |name, maxWindow = 0.05|
            SynthDef(name, {{ |out, window = 0.001, loDb = -30, hiDb = 0, loForce = 0.14, hiForce = 0.5, ref = 1|
                Out.ar(out, LoudnessToFriction.ar(sound.(), window, loDb, hiDb, loForce, hiForce, ref, maxWindow))
            }})
        }};
        // The def's bytes with maxWindow 0.0123 replaced by value, as a client without the class's
        // checks could send it.
        var patched = {{ |name, value|
            var bytes = lf.(name, 0.0123).asBytes, from = 0.0123.as32Bits, to = value.as32Bits;
            var byte = {{ |bits, k| var b = (bits >> (24 - (8 * k))) & 255; if(b > 127) {{ b - 256 }} {{ b }} }};
            (0 .. bytes.size - 4).do {{ |i|
                if((0..3).every {{ |k| bytes[i + k] == byte.(from, k) }}) {{ 4.do {{ |k| bytes[i + k] = byte.(to, k) }} }}
            }};
            bytes
        }};
        var flip = SynthDef(\\flip, {{ |out, bad|
            var window = Select.kr(LFPulse.kr(ControlRate.ir / 2), [0.002, bad]);
            Out.ar(out, LoudnessToFriction.ar(sound.(), window))
        }});
        var defs = [lf.(\\lf).asBytes, lf.(\\max01, 0.1).asBytes, lf.(\\max50, 50).asBytes, flip.asBytes,
            patched.(\\maxnan, 0/0), patched.(\\max0, 0.0), patched.(\\maxneg, -1.0), patched.(\\maxinf, inf),
            SynthDef(\\sound, {{ Out.ar(0, sound.()) }}).asBytes];
        score = Score(defs.collect {{ |bytes| [0.0, ['/d_recv', bytes]] }} ++ [
            [0.0, Synth.basicNew(\\sound, nil, 999).newMsg],
            {synths},
            [0.5, ['/c_set', 0, 0]]]);
    """, channels=len(rows) + 1, memory_kb=8192)
    sound = data[:, 0]
    assert sound.max() > 0.9 and np.abs(sound).max() <= 1, "the sound spans the clip range"
    for i, (name, _, messages, expected, mapping) in enumerate(rows):
        force = data[:, i + 1]
        what = messages[0] if messages else name
        assert np.all(np.isfinite(force)), what
        if isinstance(expected, int):
            worst = np.max(np.abs(force - reference.equations_1_and_2(sound, expected, **mapping)))
            assert worst <= 1e-6, f"{what}: worst {worst} N"
        elif isinstance(expected, float):
            assert np.all(force == np.float32(expected)), f"{what}: {np.unique(force)}"
        else:
            assert force.min() >= np.float32(0.14) and force.max() <= np.float32(0.5), what
        for message in messages:
            assert log.count(f"LoudnessToFriction: {message}") == 1, f"{message!r}:\n{log[-4000:]}"
    assert message_counts(log, "LoudnessToFriction:") == sum(len(row[2]) for row in rows), log
