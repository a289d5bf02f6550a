"""A file size limit lowered on the running server while it records (prlimit --fsize: a limit set
before boot would stop JACK's own shared memory) does not kill it with the magnet on: the write
past the limit fails with EFBIG (SIGXFSZ is ignored, host/ExitSafety.cpp), the recording stops
with one message and a kfStatus entry, the file is kept whole (whole lines, within the limit),
and the server and the force frames go on at the commanded force."""
import numpy as np
import pytest

from kfharness import paths, procs, sclang, status
from kfharness.load import realtime_allowed
from kfharness.witness import Witness
from kfstudy import readers

LIMIT_BYTES = 64 * 1024
FORCE_N = 1.0
FRAME_S = 0.001  # FrictionOut frames the force once per ms of audio time
AUDIO_FRAMES = 1000  # between the two status reads: at least one second of audio time
BLOCK_S = 64 / 48000  # scsynth's control block on the tests' JACK server


def trip_diagnosis(record):
    """Where the recording saw trips and its longest gaps between frames (host time, s): for the
    failure message of a trip the machine's stalls do not explain."""
    _, records = readers.read_session(record)
    trips = [round(f[0], 3) for tag, f in records if tag == "O" and f[1] == "watchdog"]
    frames = np.array([f[0] for tag, f in records if tag == "F"])
    if len(frames) < 2:
        return f"trips recorded at {trips}; {len(frames)} frames recorded"
    gaps = np.diff(frames)
    worst = np.argsort(gaps)[-3:][::-1]
    return (f"trips recorded at {trips}; frames recorded {frames[0]:.3f}..{frames[-1]:.3f} s, longest gaps "
            + ", ".join(f"{gaps[i] * 1000:.1f} ms after {frames[i]:.3f}" for i in worst))


def test_a_file_size_limit_stops_the_recording_and_nothing_else(jack):
    record = paths.work_dir() / "fsize-session.txt"
    record.unlink(missing_ok=True)
    # The machine's own stalls in the same window (below).
    with Witness() as witness:
        run = sclang.require_ok(sclang.run_with_server("var dev, syn, before, second;\n" + status.SC_POST + f"""
        dev = FrictionDevice.sim(s, 0, FrictionHand.speeds([[20, 10]]));
        s.sync;
        syn = {{ FrictionOut.ar(0, DC.ar({FORCE_N})) * 0 }}.play;
        0.3.wait;
        ("prlimit --pid " ++ s.pid ++ " --fsize={LIMIT_BYTES}").systemCmd;
        dev.record({sclang.sc_string(record)});
        s.sync;
        3.wait;  // about 40 kB a second of frames and reports: the limit comes after ~1.5 s
        ~kfPostStatus.(dev, "KF-STATUS-A");
        // One second of audio time (1000 frames framed), not of the wall clock: see AUDIO_FRAMES.
        second = Condition.new;
        OSCFunc({{ second.test = true; second.signal }}, '/kfAudioSecond').oneShot;
        {{ var done = Done.kr(Line.kr(0, 1, 1));
            SendReply.kr(done, '/kfAudioSecond'); FreeSelf.kr(done); Silent.ar }}.play;
        second.wait;
        ~kfPostStatus.(dev, "KF-STATUS-B");
        dev.status;
        s.sync;
        "KF-ALIVE %\n".postf(s.serverRunning);
        syn.free;
        dev.close;
        s.sync;
        """, jack, name="fsize"))
    assert run.lines("KF-ALIVE ") == [["true"]], run.output[-3000:]
    assert run.scsynth_pid is None or procs.wait_pid_gone(run.scsynth_pid, 5)
    # One message, and the status entry.
    messages = [line for line in run.output.splitlines() if "File too large" in line]
    assert any(line.startswith("kfRecord: writing") for line in messages), run.output[-3000:]
    assert sum(1 for line in messages if line.startswith("kfRecord:")) == 1, messages
    assert any(line.startswith("kfStatus 0: recording failed:") and "File too large" in line for line in messages)
    # The force frames went on, at the commanded force, after the recording stopped.
    a = status.parse(run.output, "KF-STATUS-A")[0]
    b = status.parse(run.output, "KF-STATUS-B")[0]
    # Every frame framed in that audio second reached the device: sent to the magnet or, by a
    # late pump, skipped for a newer one (Device::releaseFramesLocked), except those still in the
    # queue or the jitter buffer at B (framed within the device thread's longest loop period and
    # the release latency before it, plus the one being framed). Counted against the wall clock
    # this failed without realtime scheduling beside two CPU hogs (766 frames in 1 s: scsynth's
    # audio thread, at normal priority, stalled; the dummy driver does not catch up).
    framed = (b["frames"] + b["skippedFrames"]) - (a["frames"] + a["skippedFrames"])
    in_flight = int(np.ceil((b["loopMaxS"] + b["releaseLatencyS"]) / FRAME_S)) + 1
    assert framed >= AUDIO_FRAMES - in_flight, \
        f"the force frames stopped: {framed} of {AUDIO_FRAMES} ({in_flight} in flight)"
    assert b["lastForceN"] == pytest.approx(FORCE_N)
    # A watchdog trip is 10 ms without a frame. The device thread takes every queued frame before
    # it looks (Device::pumpLocked): only frames held at their source trip it, the audio thread
    # held. Our part of that thread is each FrictionOut block (audioCallMaxS, wall clock: a lock
    # waited on counts); under one block's time it never held the frames back, and the recording's
    # end did not either. Trips then are the server's or the machine's: beside two CPU hogs JACK
    # kept scsynth from its cycles for up to 36 ms with the machine's witness (cyclictest, SCHED_FIFO
    # 90) quiet (perf: scsynth's audio thread and jackd's asleep in JACK's waits), and this test,
    # which bounded trips by the witness's stalls, failed in CI and here on them. Without realtime
    # scheduling a block can be preempted by the hogs, so there the figure is only reported. With
    # it, a stall of the machine (a vCPU paused by the host) that falls inside a block is counted in
    # it too, up to the longest the witness saw (cyclictest at SCHED_FIFO 90, above every thread).
    print(f"KF-FIGURE fsize_watchdog_trips {b['watchdogTrips']:.0f} audio_call_max_s {b['audioCallMaxS']:.6f} "
          f"witness {witness.result}")
    if realtime_allowed():
        machine_s = witness.result["max_us"] * 1e-6 if witness.result else 0.0
        assert b["audioCallMaxS"] < BLOCK_S + machine_s, (
            f"a FrictionOut block held the audio thread {b['audioCallMaxS'] * 1000:.2f} ms, the machine stalled "
            f"{machine_s * 1000:.2f} ms at most ({b['watchdogTrips']:.0f} watchdog trips; {trip_diagnosis(record)})")
    # The file: within the limit, whole lines only, readable to its end.
    size = record.stat().st_size
    assert 0 < size <= LIMIT_BYTES
    text = record.read_bytes()
    assert text.endswith(b"\n"), "the file ends mid-line"
    header, records = readers.read_session(record)
    assert sum(1 for tag, _ in records if tag == "F") >= 500
