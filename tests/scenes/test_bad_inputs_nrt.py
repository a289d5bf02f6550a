"""Issue 13: what a user or a file sends never hangs the server or gives non-finite output,
and each problem gets one clear message (rendered by scsynth -N)."""
import numpy as np
import soundfile

from kfharness import nrt, paths

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
        var dev = FrictionDevice.sim(nil, 0, FrictionHand.speeds([[50, 1]]));
        var def = SynthDef(\\nanindex, {
            var big = DC.kr(1e30) * 1e30, nan = big - big;
            Out.ar(0, [FrictionMouseIn.ar(nan)[0], FrictionOut.ar(nan, DC.ar(1.0)),
                FrictionMouseIn.ar(0, nan)[0]])
        });
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\nanindex, nil, 1000).newMsg],
            [0.5, dev.closeMsg],
            [0.55, ['/c_set', 0, 0]]]);
    """, channels=3)
    assert np.all(np.isfinite(data))
    assert np.all(data[:, 0] == 0.0)
    assert np.allclose(data[:, 1], 0.14), "no device: the minimum force"
    t = np.arange(len(data)) / SR
    assert data[(t > 0.3) & (t < 0.45), 2].max() > 5, "a NaN origin counts as 0: the puck moves from 0"
    assert log.count("FrictionMouseIn: device nan is not a slot number 0..15") == 1, log
    assert log.count("FrictionOut: device nan is not a slot number 0..15") == 1, log
    assert log.count("FrictionMouseIn: origin nan is not finite; 0 used.") == 1, log


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
