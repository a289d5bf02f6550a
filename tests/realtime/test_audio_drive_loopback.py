"""The audio drive on a realtime server (FrictionDrive, issue 26): scsynth on the JACK dummy
driver with its drive output (out_1) connected to its own input (in_1) by jack_connect; the
looped drive is sent on to out_3, and jack_rec records out_1 (the drive), out_2 (the writer's
force, halved to fit the recording's range) and out_3. The looped drive equals the reference of
the commanded force within 1e-6 of full scale after the loop's delay, and the drive is 0 within
one block after the writer is freed, after Cmd-. and after /quit."""
import numpy as np

from kfharness import drive, paths, sclang
from kfstudy import readers

BLOCK = 64
SR = 48000
# The recording is 32-bit PCM (jack_rec): a quantum of 2^-31 = 4.7e-10 on the drive, and on the
# halved force, doubled back: up to 1 float32 ulp (1.2e-7 N at 1 N) of force, which moves the
# drive by at most 0.37 of it (the table's steepest segment, 0.25 of 0.4 full scale over 0.27 N):
# 4.4e-8. The bound, 1e-6 of full scale, is above both.
TOLERANCE = 1e-6
# A force with steps faster than the slew limit (the pulse) and a slow sine, within and past the
# device's range (0.14 .. 1.4 N).
WRITER = "{ var f = LFPulse.ar(37).range(0.2, 1.5) + SinOsc.ar(211, 0, 0.05); FrictionOut.ar(0, f); Out.ar(1, f * 0.5) }"


def segments(active):
    """(start, end) sample ranges where `active` holds."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], active.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2]))


def test_the_looped_drive_is_the_commanded_force_and_zero_after_free_cmd_period_and_quit(jack):
    work = paths.work_dir()
    drive_path = drive.write_files(work, name="rt-drive")
    wav = work / "rt-drive-loop.wav"
    wav.unlink(missing_ok=True)
    run = sclang.require_ok(sclang.run_with_server(f"""
        var dev, rec, start;
        start = {{ [{{ Out.ar(2, SoundIn.ar(0)) }}.play, {{ Out.ar(0, FrictionDrive.ar(0)) }}.play] }};
        dev = FrictionDevice.sim(s, 0);
        s.sync;
        dev.loadDrive({sclang.sc_string(drive_path)});
        "jack_connect SuperCollider:out_1 SuperCollider:in_1".systemCmd;
        start.value;
        s.sync;
        rec = ("jack_rec -f " ++ {sclang.sc_string(wav)} ++ " -d 2.0 -b 32 "
            "SuperCollider:out_1 SuperCollider:out_2 SuperCollider:out_3").unixCmd;
        0.2.wait;
        ~w = {WRITER}.play; 0.2.wait; ~w.free; 0.15.wait;
        ~w = {WRITER}.play; 0.2.wait; CmdPeriod.run; 0.15.wait;
        start.value; s.sync; ~w = {WRITER}.play; 0.2.wait;
        s.quit;
        1.0.wait;
        "KF-DONE".postln;
    """, jack, name="driveloop", server_options={"numOutputBusChannels": 3}))
    assert "KF-DONE" in run.output and "FrictionDrive:" not in run.output, run.output[-3000:]
    data, rate = readers.read_wav(wav)
    assert rate == SR
    out, force, looped = (data[:, i].astype(np.float64) for i in range(3))
    force *= 2.0
    phases = segments(force != 0)
    assert len(phases) == 3, f"writer phases {phases}"
    align = phases[0][0] % BLOCK  # a synth starts at a block border: the recording's block phase
    # The loop's delay: within the first phase, out_3 is out_1 delayed by whole JACK periods.
    a, b = phases[0]
    delays = [d for d in range(0, 4 * BLOCK + 1) if np.array_equal(looped[a + d:b], out[a:b - d])]
    assert delays, "out_3 is not a delayed copy of the drive"
    loop = delays[0]
    worst = 0.0
    for k, (start, end) in enumerate(phases):
        # From the writer's first block to the end of its last: the drive of each block is the
        # reference of the force of the block before (the first block drives 0).
        first = start - align
        m = ((end - first + BLOCK - 1) // BLOCK) * BLOCK
        combined = drive.combined_force([force[first:first + m]])
        expected = drive.reference(combined, np.ones(m // BLOCK, bool), BLOCK, SR)
        worst = max(worst, np.abs(looped[first + loop:first + m] - expected[:m - loop]).max(),
                    np.abs(out[first:first + m] - expected).max())
        # Zero within one block after the writer stopped (freed, Cmd-., /quit): the block after
        # its last is the last driven, then 0 until the next writer (or for 0.1 s after the last).
        stopped = first + m + BLOCK
        until = phases[k + 1][0] if k + 1 < len(phases) else stopped + int(0.1 * SR)
        assert until - stopped > 1000 and np.all(out[stopped:until] == 0), f"drive after the stop at {end}"
    print(f"KF-FIGURE rt_drive_loop_delay_samples {loop} max_abs_error {worst:.3g}")
    assert worst <= TOLERANCE
