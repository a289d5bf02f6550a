"""The audio drive in a Score (FrictionDrive, issue 26): its output against the slot's combined
force and the drive calibration, sample by sample, on the hard cases: the minimum (0), full
force (held at the circuit's safe current), NaN, steps faster than the slew limit, the magnet
table's points and edges, values outside the force range, two writers, a writer freed in the
middle of a block, and FrictionDrive before and after the writers in node order. Two
FrictionDrive of the slot run together: only the first in a block drives (a slot has one drive),
so the two summed on one bus are the single drive; once the first is freed, the second drives."""
import numpy as np
import soundfile

from kfharness import drive, nrt, paths

SR = 48000
BLOCK = 64


def force_script():
    """Writer A's force (N), sample by sample: 50 ms each of the minimum, a step to full force,
    NaN, the table's points 0.41 and 0.72 N, above and below the range, then values
    jumping at random over and past the range, up to 0.5 s."""
    parts = [0.14, 1.4, np.nan, 0.41, 0.72, 2.0, 0.0]
    force = np.concatenate([np.full(2400, v) for v in parts])
    jumps = np.random.default_rng(26).uniform(-0.2, 1.6, 7200)  # to 0.5 s, past A's end
    return np.concatenate([force, jumps]).astype(np.float32)


def test_the_drive_follows_the_combined_force_through_the_calibration_sample_by_sample():
    work = paths.work_dir()
    drive_path = drive.write_files(work, name="nrt-drive")
    # The same circuit with tabs between names and values: the server reads that one (tabs are
    # white space to it), and sclang must take the same audio delay from either.
    tab_path = drive.write_files(work, name="nrt-drive-tab", separator="\t")
    declared_s = drive.CIRCUIT["currentSourceLatencyS"] + drive.CIRCUIT["magnetLagS"]
    force_path = work / "nrt-drive-force.wav"
    soundfile.write(str(force_path), force_script(), SR, subtype="FLOAT")
    b_dur_s = 0.0395  # writer B lasts 1896 samples from 4992: it ends at 6888, inside block 107
    head_free_s = 0.3  # after the hard cases at fixed forces, before writer A is freed
    data, log = nrt.score_and_render("nrtdrive", f"""
        var dev = FrictionDevice.describeSim(0);
        var root = RootNode(Server.default);
        // Each drive on its own channel and on channel 4, which sums them.
        var drive = SynthDef(\\nrtdrive, {{ |out| var d = FrictionDrive.ar(0); Out.ar(out, d); Out.ar(4, d) }});
        var a = SynthDef(\\nrtdriveA, {{ var f = PlayBuf.ar(1, 10); FrictionOut.ar(0, f); Out.ar(1, f) }});
        var spaced = FrictionDevice.driveCircuitLatencyOf("{drive_path}");
        var tabbed = FrictionDevice.driveCircuitLatencyOf("{tab_path}");
        var b = SynthDef(\\nrtdriveB, {{
            var f = DC.ar(0.6) * EnvGen.ar(Env([1, 1], [{b_dur_s}]), doneAction: 2);
            FrictionOut.ar(0, f); Out.ar(2, f) }});
        // sclang's reader splits fields as the server's does: both files, the declared delays.
        if((spaced - {declared_s!r}).abs > 1e-12 or: {{ tabbed != spaced }}) {{
            Error("driveCircuitLatencyOf: % with spaces, % with tabs, declared {declared_s!r}".format(spaced, tabbed)).throw
        }};
        score = Score([
            [0.0, dev.openMsg],
            [0.0, dev.loadDriveMsg("{tab_path}")],
            [0.0, ['/b_allocRead', 10, "{force_path}"]],
            [0.0, ['/d_recv', drive.asBytes]], [0.0, ['/d_recv', a.asBytes]], [0.0, ['/d_recv', b.asBytes]],
            // One FrictionDrive before the writers in node order (channel 0), one after (3).
            [0.0, Synth.basicNew(\\nrtdrive, nil, 1000).newMsg(root, [\\out, 0], \\addToHead)],
            [0.0, Synth.basicNew(\\nrtdriveA, nil, 1001).newMsg(root, nil, \\addToTail)],
            [0.0, Synth.basicNew(\\nrtdrive, nil, 1002).newMsg(root, [\\out, 3], \\addToTail)],
            [0.105, Synth.basicNew(\\nrtdriveB, nil, 1003).newMsg(root, nil, \\addToHead)],
            [{head_free_s}, ['/n_free', 1000]],  // the head drive goes: the tail one drives from then on
            [0.45, ['/n_free', 1001]],
            [0.5, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=5)
    # The tail drive's one message (a slot has one drive), and nothing else from FrictionDrive.
    assert log.count("FrictionDrive:") == 1 and log.count("has one drive") == 1, log
    head, force_a, force_b, tail, summed = (data[:, i] for i in range(5))
    head_freed = nrt.bundle_start_sample(head_free_s, SR, BLOCK)
    # Channel 1 holds A's force as its synth read it (NaN included) until it was freed.
    a_freed = nrt.bundle_start_sample(0.45, SR, BLOCK)
    b_start = nrt.bundle_start_sample(0.105, SR, BLOCK)
    b_gone = ((b_start + round(b_dur_s * SR)) // BLOCK + 1) * BLOCK  # freed after the block it ended in
    assert np.all(force_b[b_start:b_gone] == np.float32(0.6)) and np.all(force_b[b_gone:] == 0)
    combined = drive.combined_force([force_a, force_b])
    blocks = len(combined) // BLOCK + 1
    framed = np.array([b * BLOCK < a_freed for b in range(blocks)])  # A wrote every block until freed
    expected = drive.reference(combined, framed, BLOCK, SR)
    # The drive is float32 of the same double arithmetic as the reference: equal up to one
    # rounding of the last step (1 ulp of full scale 0.4: 3e-8). Head until it is freed, then
    # tail (0 before: the head drove each block first); summed on one bus, they are the single
    # drive throughout, never more.
    for name, got, want in (("head", head, np.where(np.arange(len(expected)) < head_freed, expected, 0)),
                            ("tail", tail, np.where(np.arange(len(expected)) < head_freed, 0, expected)),
                            ("summed", summed, expected)):
        error = np.abs(got.astype(np.float64) - want).max()
        worst = int(np.argmax(np.abs(got.astype(np.float64) - want)))
        print(f"KF-FIGURE nrt_drive_{name}_max_abs_error {error:.3g} at sample {worst}")
        assert error <= 3e-8, (name, worst, got[worst], want[worst])
    assert np.all(tail[:head_freed] == 0) and np.abs(expected[head_freed:]).max() > 0
    # The hard cases seen in the one drive of the slot, not only through the reference:
    # The safe current (1.8 of 2 A: drive 0.9) through 0.5 A/V of 10 V, inverted; the drive level
    # is a float (ForceSafety::driveLevel), 0.9 rounded to float32 first.
    full = np.float32(-float(np.float32(0.9)) * 2 / 0.5 / 10)
    assert np.all(summed[:BLOCK] == 0) and np.all(summed[BLOCK:2400 + BLOCK] == 0)  # the minimum: 0
    # The step to 1.4 N rises at 2000 N/s (0.0417 N a sample) until the safe drive 0.9, which the
    # table gives at 0.72 + 0.8 * 0.68 = 1.264 N: (1.264 - 0.14) / 0.0417 = 26.98, the 27th sample.
    ramp = summed[2400 + BLOCK:2400 + BLOCK + 100].astype(np.float64)
    at_full = int(np.argmax(ramp == full))
    assert at_full == 26 and np.all(np.diff(ramp[:at_full + 1]) < 0) and np.all(ramp[at_full:] == full)
    assert summed.min() >= full and summed.max() <= 0  # never past the safe range, one sign
    assert b_start > 4800 + BLOCK + 100 and summed[4800 + BLOCK + 100] == 0  # NaN alone: the minimum, 0
    assert summed[7200 + BLOCK + 1000] == np.float32(-0.25 * 0.4)  # 0.41 N: the table's point 0.25
    assert summed[9600 + BLOCK + 1000] == np.float32(-0.5 * 0.4)
    # Freed writer A: the block after its last one drives 0, at once.
    assert np.count_nonzero(summed[a_freed:a_freed + BLOCK]) > BLOCK // 2  # its last block, driven
    assert np.all(summed[a_freed + BLOCK:] == 0)
