"""One puck, one force in Score renders (lockstep, issue 14): readers started at different
times agree to the sample, kfZero re-bases them all at one block, and several FrictionOut on a
slot give one combined frame per millisecond."""
import numpy as np

from kfharness import nrt, paths

SR = 48000


def read_frames(path):
    lines = [l.split() for l in open(path) if l.strip() and not l.startswith("#")]
    return np.array([[float(v) for v in l[1:]] for l in lines[1:] if l[0] == "F"])


def test_readers_agree_to_the_sample_late_readers_start_where_the_puck_is_and_zero_rebases_all():
    data, _ = nrt.score_and_render("onepos", """
        var dev = FrictionDevice.describeSim(0, FrictionHand.speeds([[20, 1], [-30, 1], [40, 2]]));
        var def = SynthDef(\\onepos, { |out| Out.ar(out, FrictionMouseIn.ar(0)[0]) });
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\onepos, nil, 1000).newMsg(nil, [\\out, 0])],
            [1.5, Synth.basicNew(\\onepos, nil, 1001).newMsg(nil, [\\out, 1])],
            [2.5, dev.setPositionMsg(100, 0)],
            [3.5, dev.closeMsg],
            [3.55, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=2)
    a, b = data[:, 0].astype(np.float64), data[:, 1].astype(np.float64)
    start_b = int(np.argmax(b != 0))
    assert abs(start_b / SR - 1.5) < 0.002
    both = slice(start_b, int(3.49 * SR))
    diff = np.abs(a[both] - b[both]).max()
    print(f"KF-FIGURE nrt_readers_max_abs_difference_mm {diff} late_reader_first_x_mm {b[start_b]:.4f}")
    assert diff == 0.0
    assert b[start_b] == a[start_b] and abs(b[start_b]) > 5
    # kfZero (setPosition 100 mm) at 2.5 s: one step, at one block, in both readers; the
    # movement goes on from 100 mm.
    zero = int(2.5 * SR)
    steps = np.abs(np.diff(a[zero - 256:zero + 256]))
    print(f"KF-FIGURE nrt_setPosition_step_mm {steps.max():.3f} at sample {zero - 256 + int(np.argmax(steps)) + 1}")
    assert steps.max() > 90 and np.sum(steps > 1) == 1
    assert (zero - 256 + int(np.argmax(steps)) + 1) % 64 == 0, "at a block boundary"
    assert abs(a[zero + 128] - 100) < 1.0


def test_several_writers_in_a_score_one_frame_per_millisecond_by_the_rule():
    rec = paths.work_dir() / "nrt-writers.kfs"
    nrt.score_and_render("nrtwriters", f"""
        var dev = FrictionDevice.describeSim(0);
        var def = SynthDef(\\nrtwriter, {{ |force = 0.14| FrictionOut.ar(0, DC.ar(force)) }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, dev.recordMsg("{rec}")],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\nrtwriter, nil, 1000).newMsg(nil, [\\force, 0.3])],
            [0.0, Synth.basicNew(\\nrtwriter, nil, 1001).newMsg(nil, [\\force, 1.0])],
            [0.0, Synth.basicNew(\\nrtwriter, nil, 1002).newMsg(nil, [\\force, 0.14])],
            [0.5, ['/n_free', 1001]],
            [1.0, dev.closeMsg],
            [1.05, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=1)
    frames = read_frames(rec)
    t, commanded = frames[:, 1], frames[:, 3]
    per_ms = np.bincount(np.round(t * 1000).astype(int))  # frames start on whole ms
    print(f"KF-FIGURE nrt_three_writers_frames_per_ms min {per_ms[1:999].min()} max {per_ms[1:999].max()}")
    assert per_ms[1:999].min() == 1 and per_ms[1:999].max() == 1
    assert np.allclose(commanded[(t > 0.05) & (t < 0.49)], 1.16, atol=1e-4)
    assert np.allclose(commanded[(t > 0.51) & (t < 0.99)], 0.3, atol=1e-4)  # one writer freed


def test_a_device_object_stands_for_its_slot_in_ugens_and_synth_arguments():
    """FrictionMouseIn.ar(dev), FrictionOut.ar(dev, ...) and Synth's [\\device, dev] take the
    FrictionDevice as a Buffer is taken for its bufnum: slot 3 is read and written."""
    rec = paths.work_dir() / "nrt-device-object.kfs"
    data, _ = nrt.score_and_render("devobject", f"""
        var dev = FrictionDevice.describeSim(3, FrictionHand.speeds([[20, 2]]));
        var reader = SynthDef(\\devreader, {{ Out.ar(0, [FrictionMouseIn.ar(dev)[0], FrictionMouseIn.ar(3)[0]]) }});
        var writer = SynthDef(\\devwriter, {{ |device = 0| FrictionOut.ar(device, DC.ar(0.2)) }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, dev.recordMsg("{rec}")],
            [0.0, ['/d_recv', reader.asBytes]],
            [0.0, ['/d_recv', writer.asBytes]],
            [0.0, Synth.basicNew(\\devreader, nil, 1000).newMsg(nil)],
            [1.0, Synth.basicNew(\\devwriter, nil, 1001).newMsg(nil, [\\device, dev])],
            [1.2, dev.closeMsg],
            [1.25, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=2)
    by_object, by_number = data[:, 0], data[:, 1]
    print(f"KF-FIGURE nrt_device_object_reader_max_x_mm {by_object.max():.3f}")
    assert by_object.max() > 1, "the puck moved"
    assert np.array_equal(by_object, by_number), "the object reads slot 3"
    frames = read_frames(rec)
    assert frames.ndim == 2, "no force frame on slot 3"
    t, commanded = frames[:, 1], frames[:, 3]
    assert np.allclose(commanded[(t > 1.02) & (t < 1.18)], 0.2, atol=1e-4), "the writer drives slot 3"
