"""The device layer in Score renders: a simulated device stepped in lockstep with audio time,
record and replay, and closed slots."""
import numpy as np

from kfharness import nrt, paths, sclang_session
from kfstudy import readers

SR = 48000
HID_FILE = paths.test_data_dir() / "hid" / "genius-gila-gaming-mouse-0458-0138.hid"


def render_device(name, open_code, seconds, force="DC.ar(0.3)", extra_events="", interpolation=1):
    """Renders FrictionMouseIn's four outputs and FrictionOut's commanded force."""
    return nrt.score_and_render(name, f"""
        var dev = {open_code};
        var def = SynthDef(\\{name}, {{
            Out.ar(0, FrictionMouseIn.ar(0, 0, {interpolation}) ++ [FrictionOut.ar(0, {force})])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\{name}, nil, 1000).newMsg],
            {extra_events}
            [{seconds}, dev.closeMsg],
            [{seconds} + 0.05, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=5)


def test_steady_100_mm_per_s_hand_reads_100_mm_per_s_within_one_speed_level():
    data, _ = render_device("steady", "FrictionDevice.describeSim(0, FrictionHand.speeds([[100, 3]]))", 2.0)
    t = np.arange(len(data)) / SR
    steady = (t > 1.0) & (t < 1.9)  # after the hand has taken up its lag
    speed = data[steady, 2]
    assert abs(speed.mean() - 100) < 2.6
    assert np.all(np.abs(speed - 100) <= 2.625 + 1e-3), "each reading is one of the two levels around 100"
    levels = np.unique(np.round(speed / 2.625, 6))
    assert np.allclose(levels, np.round(levels)), "speed comes in 2.625 mm/s levels"
    position = data[steady, 0]
    assert abs(np.polyfit(t[steady], position, 1)[0] - 100) < 1.0


def test_force_frames_reach_the_simulated_magnet_and_it_turns_off_at_close(tmp_path=paths.work_dir()):
    rec = tmp_path / "frames.kfs"
    data, _ = render_device("frames", "FrictionDevice.describeSim(0, FrictionHand.speeds([[60, 2]]))", 1.0,
                            force="LFPulse.ar(50).range(0.2, 0.8)",
                            extra_events=f"[0.0, dev.recordMsg(\"{rec}\")],")
    session = readers.Session(rec)
    frames, offs = session.frames, session.offs
    # Frames are the 1 ms means of the force: at 50 Hz each 10 ms half-period is 10 whole frames.
    assert len(frames) > 950
    commanded = frames[:, 3].astype(np.float32)  # written as floats
    square = {np.float32(0.2), np.float32(0.8)}
    assert set(np.unique(commanded)) <= square, "square frames pass unchanged (within range)"
    assert np.sum(commanded == np.float32(0.8)) > 450
    assert offs and abs(offs[-1] - 1.0) < 0.002, "magnet off when the slot closes"
    # FrictionOut outputs what it commanded: the same frames, once complete.
    out_force = data[:, 4]
    assert set(np.unique(out_force[SR // 100: SR - 100])) <= square


def frame_line(frames, frequency_hz):
    """The amplitude of the commanded frames' line at frequency_hz (its alias, above half the frame
    rate), fitted by least squares to the frames after the first 10 ms."""
    t, force = frames[:, 1], frames[:, 3]
    keep = t > 0.01
    basis = np.column_stack([np.sin(2 * np.pi * frequency_hz * t[keep]), np.cos(2 * np.pi * frequency_hz * t[keep]),
                             np.ones(keep.sum())])
    (a, b, _), *_ = np.linalg.lstsq(basis, force[keep], rcond=None)
    return np.hypot(a, b)


def test_at_8_khz_the_frames_keep_a_2_khz_texture_and_leave_out_a_6_khz_one(tmp_path=paths.work_dir()):
    # A device whose force rate is 8 kHz frames FrictionOut through the anti-alias filter
    # (dsp/FrameFilter.hpp; its response is tested exactly in tests/dsp/test_force_framer.cpp):
    # here, end to end through the plugin, what the device records, against the design's claims.
    # A 0.1 N sine about 0.77 N at 2 kHz (0.25 of the frame rate): with the board's hold
    # (sinc(0.25) = 0.900) within one Weber fraction (0.11) of its height; frame means would give
    # 0.90 x 0.90 = 0.81 and fail. At 6 kHz (0.75 of the rate, folding to 2 kHz): under -30 dB;
    # frame means would pass 0.30 (-10 dB). 0.1 N, because the device's slew limit (2000 N/s) holds
    # a 2 kHz line to 2000 / (2 pi 2000) = 0.16 N: under it the commanded force is the framed one.
    lines = {}
    for hz in (2000, 6000):
        rec = tmp_path / f"frames-8k-{hz}.kfs"
        render_device(f"frames8k{hz}", "FrictionDevice.describeSim(0, profile: (forceFramePeriodS: 0.000125))", 0.5,
                      force=f"SinOsc.ar({hz}, 0, 0.1, 0.77)", extra_events=f"[0.0, dev.recordMsg(\"{rec}\")],")
        frames = readers.Session(rec).frames.astype(np.float64)
        period = np.median(np.diff(frames[:, 1]))
        assert abs(period - 0.000125) < 1e-9, f"frames {period * 1e6:.1f} us apart"
        settled = frames[:, 1] > 0.01  # the slew up from the minimum at the start takes 3 frames
        np.testing.assert_allclose(frames[settled, 3], frames[settled, 2], atol=1e-6, err_msg="commanded as framed")
        lines[hz] = frame_line(frames, hz) / 0.1
    assert abs(lines[2000] * np.sinc(0.25) - 1) < 0.11, lines
    assert lines[6000] < 10 ** (-30 / 20), lines


def test_friction_slows_the_puck_as_the_simulation_says():
    slow, _ = render_device("heavy", "FrictionDevice.describeSim(0, FrictionHand.path([[0, 0], [1, 40]]))", 1.0,
                            force="DC.ar(1.4)")
    fast, _ = render_device("light", "FrictionDevice.describeSim(0, FrictionHand.path([[0, 0], [1, 40]]))", 1.0,
                            force="DC.ar(0.14)")
    i = int(0.6 * SR)
    assert slow[i, 0] < fast[i, 0] - 5, f"{slow[i, 0]} mm with 1.4 N vs {fast[i, 0]} mm with 0.14 N"


def test_out_of_range_force_is_clamped_and_nan_is_the_minimum():
    data, _ = render_device("clamp", "FrictionDevice.describeSim(0)", 0.3,
                            force="Select.ar(LFPulse.ar(10, 0, 0.5), [DC.ar(5), DC.ar(1e30) * 1e30 - (DC.ar(1e30) * 1e30)])")
    force = data[: int(0.29 * SR), 4]
    assert np.all(np.isfinite(force))
    assert force.min() == np.float32(0.14) and force.max() == np.float32(1.4)
    # Whole frames of 5 N read 1.4 N, whole frames of NaN 0.14 N (a frame that straddles LFPulse's
    # switch mixes the two).
    values, counts = np.unique(force, return_counts=True)
    assert set(values[counts > 48 * 20]) == {np.float32(0.14), np.float32(1.4)}


def test_record_then_replay_gives_identical_output():
    rec = paths.work_dir() / "session.kfs"
    recorded, _ = render_device(
        "rec", "FrictionDevice.describeSim(0, FrictionHand.path([[0, 0], [0.5, 30], [1.0, 10], [1.5, 45]]), "
        "(reportJitterS: 0.0005, dropProbability: 0.05, seed: 7))", 1.6,
        extra_events=f"[0.0, dev.recordMsg(\"{rec}\")],")
    replayed, _ = render_device("replay", f"FrictionDevice.describeReplay(\"{rec}\")", 1.6)
    reports = readers.Session(rec).reports
    assert len(reports) > 150
    assert np.max(np.abs(recorded[:, 0])) > 25
    np.testing.assert_array_equal(recorded[:, :4], replayed[:, :4])


def test_hid_recorder_file_replays_through_the_ugens():
    data, log = render_device("hid", f"FrictionDevice.describeReplay(\"{HID_FILE}\")", 9.0)
    x, y = data[:, 0].astype(np.float64), data[:, 1].astype(np.float64)
    # The recording's relative X and Y sum to -67 and -40 counts (decoded independently in the
    # device tests); at 0.021 mm a count the puck ends there.
    assert abs(x[-int(0.1 * SR)] - (-67 * 0.021)) < 1e-4, x[-int(0.1 * SR)]
    assert abs(y[-int(0.1 * SR)] - (-40 * 0.021)) < 1e-4
    assert np.all(np.isfinite(data))


def test_closed_slot_gives_zero_position_minimum_force_and_one_warning_each():
    data, log = nrt.score_and_render("closed", """
        var def = SynthDef(\\closed, { Out.ar(0, FrictionMouseIn.ar(3) ++ [FrictionOut.ar(3, DC.ar(0.9))]) });
        score = Score([
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\closed, nil, 1000).newMsg],
            [0.2, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=5)
    assert np.all(data[:, :4] == 0.0)
    assert np.all(data[:, 4] == np.float32(0.14))
    assert log.count("FrictionMouseIn: no device is open at index 3") == 1
    assert log.count("FrictionOut: no device is open at index 3") == 1


def test_same_score_renders_the_same_file_sample_for_sample():
    open_code = ("FrictionDevice.describeSim(0, FrictionHand.path([[0, 0], [0.4, 20], [0.8, 5]]), "
                 "(reportJitterS: 0.001, dropProbability: 0.1))")
    a, _ = render_device("det_a", open_code, 0.9, force="LoudnessToFriction.ar(SinOsc.ar(FrictionMouseIn.ar(0)[2].abs * 10))")
    b, _ = render_device("det_b", open_code, 0.9, force="LoudnessToFriction.ar(SinOsc.ar(FrictionMouseIn.ar(0)[2].abs * 10))")
    np.testing.assert_array_equal(a, b)


def test_bad_device_arguments_give_clear_errors():
    out = sclang_session.run("""
        var errors = List.new;
        [
            { FrictionHand.path([[0, 0], [-1, 3]]) },
            { FrictionHand.speeds([[10, -1]]) },
            { FrictionHand.path([]) },
            { FrictionDevice.describeSim(16) },
            { FrictionDevice.describeSim(0, 3) },
            { FrictionDevice.describeSim(0, nil, (maxForceN: "x")) },
            { SynthDef(\\x, { FrictionMouseIn.ar(0, 0, 5) }).add },
            { SynthDef(\\y, { FrictionOut.ar(-1, 0.2) }).add },
            // A nil server is Server.default (not booted here), as everywhere in SC: no silent
            // description of a device that is not open.
            { FrictionDevice.sim(nil, 0) }
        ].do { |f| try { f.value } { |e| errors.add(e.errorString) } };
        errors.do(_.postln);
        if(errors.size != 9) { Error("expected 9 errors, got %".format(errors.size)).throw };
    """)
    for text in ["times must ascend", "durations must be >= 0", "non-empty array", "index must be an Integer from 0 to 15",
                 "hand must be a FrictionHand", "must be a number", "interpolation must be 0", "device must be a slot index",
                 "FrictionDevice.sim: server localhost is not running"]:
        assert text in out, text


def test_specs_names_carry_units_old_names_still_work_and_audio_delay_is_one_ms():
    out = sclang_session.run("""
        var d = FrictionDevice.describeSim(0), e = FrictionDevice.describeSim(1, nil, (maxForce: 1.0, tactileLatencyS: 0.003));
        [\\countMm, \\updateRateHz, \\maxSpeedMmPerS, \\minForceN, \\maxForceN, \\audioLatencyS, \\tactileLatencyS].do { |k|
            "UNIT % %".format(k, d.specs[k]).postln };
        [\\countMm, \\updateRate, \\maxSpeed, \\minForce, \\maxForce, \\audioLatency, \\tactileLatency].do { |k|
            "SPEC % %".format(k, d.specs[k]).postln };
        "DELAY %".format(d.audioDelay.round(1e-9)).postln;
        "E % %".format(e.specs[\\maxForce], e.audioDelay.round(1e-9)).postln;
        "EMSG %".format(e.openMsg).postln;
    """)
    for line in ["UNIT countMm 0.021", "UNIT updateRateHz 125", "UNIT maxSpeedMmPerS 333.375", "UNIT minForceN 0.14",
                 "UNIT maxForceN 1.4", "UNIT audioLatencyS 0.0014", "UNIT tactileLatencyS 0.0024"]:
        assert line in out, line
    # The names without units of earlier versions, as a user may have typed them.
    for line in ["SPEC countMm 0.021", "SPEC updateRate 125", "SPEC maxSpeed 333.375", "SPEC minForce 0.14",
                 "SPEC maxForce 1.4", "SPEC audioLatency 0.0014", "SPEC tactileLatency 0.0024", "DELAY 0.001",
                 "E 1.0 0.0016"]:
        assert line in out, line
    assert "maxForceN, 1.0" in out and "tactileLatencyS, 0.003" in out, "profile names reach the server by setting name"


def test_a_device_opened_later_in_a_score_starts_its_time_at_the_open():
    """Device time starts at the open, as in realtime: a hand script opened at 0.5 s runs from
    the block the open ran at (scsynth: 0.5 s, 375 blocks of 64 at 48 kHz)."""
    hand = "FrictionHand.path([[0, 0], [0.3, 20], [0.6, 5]])"
    early, _ = render_device("open_early", f"FrictionDevice.describeSim(0, {hand})", 1.2)
    late, _ = nrt.score_and_render("open_late", f"""
        var dev = FrictionDevice.describeSim(0, {hand});
        var def = SynthDef(\\open_late, {{
            Out.ar(0, FrictionMouseIn.ar(0, 0, 1) ++ [FrictionOut.ar(0, DC.ar(0.3))])
        }});
        score = Score([
            [0.5, dev.openMsg],
            [0.5, ['/d_recv', def.asBytes]],
            [0.5, Synth.basicNew(\\open_late, nil, 1000).newMsg],
            [1.7, dev.closeMsg],
            [1.75, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=5)
    # The block the open and the synth ran at: FrictionOut outputs the minimum force from its
    # first block. 0.5 s under scsynth; one block later under supernova, which runs a bundle a
    # block after scsynth does (nrt.bundle_start_sample): device time starts at that open.
    shift = int(np.argmax(late[:, 4] != 0))
    assert shift == nrt.bundle_start_sample(0.5, SR), f"the synth started at sample {shift}"
    n = int(1.1 * SR)
    assert np.max(np.abs(early[:n, 0])) > 3, "the puck moved"
    # The same motion, from the open on. Not bit for bit: report times are rendered against
    # absolute audio time, so a report may land one sample apart (a speed step a sample early or
    # late).
    np.testing.assert_allclose(late[shift:shift + n, 0], early[:n, 0], atol=0.021)
    speed_differs = np.abs(late[shift:shift + n, 2] - early[:n, 2]) > 1e-3
    assert np.mean(speed_differs) < 1e-3


def test_a_held_hand_starts_its_movement_at_the_release():
    """A device opened with (handHeld: true) rests until releaseHand, and its hand then moves the
    puck as a free one from its open. The release at sample 24192 (0.504 s: whole blocks of 64 and
    whole reports of 8 ms, so the reports fall at the same moments of the movement)."""
    hand = "FrictionHand.path([[0, 0], [0.3, 20], [0.6, 5]])"
    release_sample = 378 * 64
    # supernova runs a bundle a block after its stamp (nrt.bundle_start_sample).
    release_s = next(t for t in (0.504, 0.504 - 64 / SR) if nrt.bundle_start_sample(t, SR) == release_sample)
    free, refused = render_device("hand_free", f"FrictionDevice.describeSim(0, {hand})", 1.2,
                                  extra_events="[0.1, dev.releaseHandMsg],")
    assert "kfSimRelease: device 0 is not a simulated device opened with its hand held" in refused
    held, _ = render_device("hand_held", f"FrictionDevice.describeSim(0, {hand}, (handHeld: true))", 1.8,
                            extra_events=f"[{release_s!r}, dev.releaseHandMsg],")
    assert np.all(held[:release_sample, [0, 2]] == 0), "the puck rests until the release"
    n = int(1.1 * SR)
    assert np.max(np.abs(free[:n, 0])) > 3, "the hand moved the puck"
    # The same reports at the same moments of the movement: equal but for rounding (under a
    # two-hundredth of a count of 0.021 mm).
    np.testing.assert_allclose(held[release_sample:release_sample + n, 0], free[:n, 0], atol=1e-4)
