"""The audio drive on a realtime server (FrictionDrive, issue 26): scsynth on the JACK dummy
driver with its drive output (out_1) connected to its own input (in_1) by jack_connect. Inside
scsynth, a capture synth at the tail keeps every block of the drive (bus 0), the writer's force
(bus 1, halved) and the looped drive (in_1) in a buffer; outside, jack_rec records out_1, out_2
and out_3 (the looped drive sent on). The looped drive equals the reference of the commanded
force within 1e-6 of full scale after the loop's delay, and the drive is 0 within one block after
the writer is freed, after Cmd-. and after /quit.

Why both: jack_rec is a JACK client of its own, at normal priority without realtime scheduling,
and when it does not get the CPU within a period it loses that period (scsynth goes on): one
64-sample block of all three channels was missing from a recording beside two CPU hogs (the
writer's 211 Hz sine jumped by 101 degrees, one block's worth, and the drive after it referred to
a force no longer in the file; jackd logged 446 'jackrec was not finished'). The capture runs in
scsynth's own audio thread, in the very blocks it checks, so it cannot lose one; it is freed with
everything else by Cmd-. and gone with the server, so the drive after those two is read from
jack_rec's file, where a lost period can drop a zero but never make one up."""
import numpy as np

from kfharness import drive, paths, sclang
from kfstudy import readers

BLOCK = 64
SR = 48000
# The captures are written as 32-bit float: the drive and the halved force exactly (halving and
# doubling back are exact in float32). The bound, 1e-6 of full scale:
TOLERANCE = 1e-6
CAPTURE_S = 2.0  # each capture buffer's length; the scene captures at most 0.8 s of wall clock
# jack_rec's ring buffer (-B, frames): more than the 2 s it records, so that its disk thread, however
# late, never finds it full. Its process callback writes each channel's sample apart, and on a full
# buffer drops some of a frame's and not the others, shifting every later frame's channels: beside a
# second test command (fresh clone 66) its file at the default 16384 frames (0.34 s) read out_2 as
# 7355 short runs. Not a lost period, which the test allows for.
JACK_REC_FRAMES = 131072
# A force with steps faster than the slew limit (the pulse) and a slow sine, within and past the
# device's range (0.14 .. 1.4 N).
WRITER = "{ var f = LFPulse.ar(37).range(0.2, 1.5) + SinOsc.ar(211, 0, 0.05); FrictionOut.ar(0, f); Out.ar(1, f * 0.5) }"


def segments(active):
    """(start, end) sample ranges where `active` holds."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], active.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2]))


def blocks_up(n):
    return ((n + BLOCK - 1) // BLOCK) * BLOCK


def test_the_looped_drive_is_the_commanded_force_and_zero_after_free_cmd_period_and_quit(jack):
    work = paths.work_dir()
    drive_path = drive.write_files(work, name="rt-drive")
    wav = work / "rt-drive-loop.wav"
    captures = [work / f"rt-drive-capture{i}.wav" for i in range(2)]
    for path in [wav, *captures]:
        path.unlink(missing_ok=True)
    run = sclang.require_ok(sclang.run_with_server(f"""
        var dev, rec, start, bufs, capture, capturing;
        start = {{ [{{ Out.ar(2, SoundIn.ar(0)) }}.play, {{ Out.ar(0, FrictionDrive.ar(0)) }}.play] }};
        // [drive, force / 2, looped drive, 1 where captured], every block from its start, after
        // every other synth (the tail): a block's own drive and force.
        bufs = 2.collect {{ Buffer.alloc(s, {int(CAPTURE_S * SR)}, 4) }};
        capture = {{ |buf| {{ RecordBuf.ar([In.ar(0), In.ar(1), SoundIn.ar(0), DC.ar(1)], buf, loop: 0,
            doneAction: 2); Silent.ar }}.play(s, addAction: \\addToTail) }};
        dev = FrictionDevice.sim(s, 0);
        s.sync;
        dev.loadDrive({sclang.sc_string(drive_path)});
        "jack_connect {jack.sc_client}:out_1 {jack.sc_client}:in_1".systemCmd;
        start.value;
        s.sync;
        rec = ("jack_rec -f " ++ {sclang.sc_string(wav)} ++ " -d 2.0 -b 32 -B {JACK_REC_FRAMES} "
            "{jack.sc_client}:out_1 {jack.sc_client}:out_2 {jack.sc_client}:out_3").unixCmd;
        capture.(bufs[0]);
        s.sync;
        0.2.wait;
        ~w = {WRITER}.play; 0.2.wait; ~w.free; 0.15.wait;
        ~w = {WRITER}.play; 0.2.wait; CmdPeriod.run; 0.15.wait;
        start.value; capturing = capture.(bufs[1]); s.sync; ~w = {WRITER}.play; 0.2.wait;
        capturing.free;
        s.sync;
        bufs[0].write({sclang.sc_string(captures[0])}, "wav", "float");
        bufs[1].write({sclang.sc_string(captures[1])}, "wav", "float");
        s.sync;
        s.quit;
        1.0.wait;
        "KF-DONE\n".post;
    """, jack, name="driveloop", server_options={"numOutputBusChannels": 3}))
    assert "KF-DONE" in run.output and "FrictionDrive:" not in run.output, run.output[-3000:]

    # The captures: the first from before the first writer to Cmd-. (the writer freed, then the
    # one Cmd-. stopped), the second from the restart to its end, the third writer still running.
    loop, worst = None, 0.0
    for c, path in enumerate(captures):
        data, rate = readers.read_wav(path)
        assert rate == SR
        n = int(np.count_nonzero(data[:, 3] == 1))
        assert n > 0 and np.all(data[:n, 3] == 1) and n % BLOCK == 0, f"capture {c}: {n} samples"
        out, force, looped = (data[:n, i].astype(np.float64) for i in range(3))
        force *= 2.0
        phases = segments(force != 0)
        assert len(phases) == (2, 1)[c], f"capture {c}: writer phases {phases}"
        if loop is None:
            # The loop's delay: within the first phase, the looped drive is the drive delayed by
            # whole JACK periods.
            a, b = phases[0]
            delays = [d for d in range(0, 4 * BLOCK + 1) if np.array_equal(looped[a + d:b], out[a:b - d])]
            assert delays, "the looped drive is not a delayed copy of the drive"
            loop = delays[0]
        for k, (first, end) in enumerate(phases):
            # A synth starts at a block border, as the capture did. From the writer's first block
            # to the end of its last (or of the capture): the drive of each block is the reference
            # of the force of the block before (the first block drives 0).
            assert first % BLOCK == 0
            m = min(blocks_up(end - first), n - first)
            combined = drive.combined_force([force[first:first + m]])
            expected = drive.reference(combined, np.ones(m // BLOCK, bool), BLOCK, SR)
            worst = max(worst, np.abs(looped[first + loop:first + m] - expected[:m - loop]).max(),
                        np.abs(out[first:first + m] - expected).max())
            if c == 0 and k == 0:
                # Zero within one block after the writer was freed: the block after its last is
                # the last driven, then 0 until the next writer.
                stopped = first + m + BLOCK
                assert phases[1][0] - stopped > 1000 and np.all(out[stopped:phases[1][0]] == 0), \
                    f"drive after the free at {end}"
    print(f"KF-FIGURE rt_drive_loop_delay_samples {loop} max_abs_error {worst:.3g}")
    assert worst <= TOLERANCE

    # jack_rec: zero within one block after Cmd-. and after /quit, until the next writer (or for
    # 0.1 s after the last).
    data, rate = readers.read_wav(wav)
    assert rate == SR
    out, force = data[:, 0].astype(np.float64), data[:, 1].astype(np.float64)
    phases = segments(force != 0)
    assert len(phases) == 3, f"writer phases in jack_rec's file {phases}"
    align = phases[0][0] % BLOCK  # a synth starts at a block border: the recording's block phase
    for k in (1, 2):
        start, end = phases[k]
        stopped = align + blocks_up(end - align) + BLOCK
        until = phases[k + 1][0] if k + 1 < len(phases) else stopped + int(0.1 * SR)
        assert until - stopped > 1000 and np.all(out[stopped:until] == 0), f"drive after the stop at {end}"
