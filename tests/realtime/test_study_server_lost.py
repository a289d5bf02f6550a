"""A study session whose instrument is gone mid-threshold-condition fails at once: its server dies
(kill -9 of scsynth, or of jackd: the server's audio stops), its device's slot is closed under it,
its device recording stops (a file size limit: as a full disk), or sclang itself stands still
(stopped by SIGSTOP for 5 s, as a computer that slept), or the device's thread fails. Checked: the session's state, its reason in
session.csv and the condition's events, and no trial stored after the death (FrictionStudySession's
watch: a /sync every 0.25 s, lost after lostAfterS; the device's status each tick; the watch's own
tick late by more than lostAfterS). And sclang killed, its server playing on: the server stops the
force and the recordings by itself."""
import shutil
import time

import numpy as np
import pytest
import soundfile

from kfharness import paths, procs, sclang
from kfstudy import readers
from kfstudy.session_folder import read_csv

SCRIPT = r"""
var study, session, path = @ROOT@ +/+ "L1/trials.csv", killT, overT, atKill, atOver, later;
var rows = { if(File.exists(path)) { File.readAllString(path).split($\n).reject(_.isEmpty).size - 1 } { 0 } };
study = FrictionStudy("lost", [
	FrictionStudyCondition.threshold(\forceStep, {
		FrictionThreshold.force(FrictionConstantStimuli([0.05, 0.1, 0.2], 10, seed: 3), 0.3, 0.15, 0.05, seed: 2)
	}, "Which interval held more friction?", [], 120, \keys, { |seed| FrictionObserver(0.1, 3.5, 0.02, seed: seed) })]);
session = study.run("L1", @ROOT@, s, simulated: FrictionStudySimParticipant(4, 2), windows: false);
session.onEnd = { overT = Main.elapsedTime; atOver = rows.value };
while { rows.value < 3 } { 0.01.wait };
@ACTION@
atKill = rows.value;
while { session.isOver.not and: { Main.elapsedTime - killT < 30 } } { 0.05.wait };
3.wait;  // what a session that went on would store meanwhile: a trial every 0.4 s
later = rows.value;
"KF-STATE %\n".postf(session.state);
"KF-LOST-AFTER %\n".postf(FrictionStudySession.lostAfterS);
"KF-DEATH-TO-FAILURE %\n".postf(overT !? { overT - killT });
"KF-ROWS % % %\n".postf(atKill, atOver, later);
"""


STOPPED_S = 5  # how long sclang is stopped (SIGSTOP, then SIGCONT)
ACTIONS = {
    "scsynth": '("kill -9 " ++ s.pid).systemCmd;\nkillT = Main.elapsedTime;',
    "jackd": '("kill -9 " ++ @JACKD@).systemCmd;\nkillT = Main.elapsedTime;',
    # Its slot closed as another client (or a failed reopen) would close it.
    "device": "s.sendMsg('/cmd', \\kfClose, 0);\nkillT = Main.elapsedTime;",
    # Its thread fails, as when a driver loses its device (the simulated device's kfSimFail).
    "failing": "s.sendMsg('/cmd', \\kfSimFail, 0);\nkillT = Main.elapsedTime;",
    # The server may write 2000 bytes more into any file (its device recording grows by about 40 kB
    # a second): the recording stops on the write that would pass it (SIGXFSZ ignored).
    "recording": 'killT = Main.elapsedTime;\n("prlimit --pid " ++ s.pid ++ " --fsize=" ++ (File.fileSize(@ROOT@ +/+ '
                 '"L1/01-forceStep/device.kfsession") + 2000)).systemCmd;',
    # The shell stops sclang, waits, and lets it go on: sclang's clock runs on meanwhile.
    "sclang": 'killT = Main.elapsedTime;\n"kill -STOP %; sleep @STOPPED@; kill -CONT %".format(thisProcess.pid, '
              'thisProcess.pid).systemCmd;',
}
REASONS = {"scsynth": "stopped answering", "jackd": "stopped answering", "device": "closed under the session",
           "failing": "failed (threadStopped",
           "recording": "stopped (the post window says why)", "sclang": "sclang stood still"}


@pytest.mark.parametrize("victim", list(ACTIONS))
def test_a_dead_server_fails_the_session_at_once_and_nothing_is_stored_after(jack, victim):
    root = paths.work_dir() / f"study-server-lost-{victim}"
    shutil.rmtree(root, ignore_errors=True)
    action = sclang.fill(ACTIONS[victim], JACKD=jack.proc.pid, STOPPED=STOPPED_S, ROOT=sclang.sc_string(str(root)))
    run = sclang.run_with_server(sclang.fill(SCRIPT, ROOT=sclang.sc_string(str(root)), ACTION=action), jack,
                                 timeout=90, name="study-server-lost", server_options={"numOutputBusChannels": 4})
    assert run.lines("KF-STATE") == [["failed"]], run.output[-3000:]
    lost_after_s = float(run.lines("KF-LOST-AFTER")[0][0])
    death_to_failure_s = float(run.lines("KF-DEATH-TO-FAILURE")[0][0])
    print(f"KF-FIGURE study_{victim}_death_to_session_failure_s {death_to_failure_s:.3f}")
    if victim in ("device", "failing", "recording"):
        # Found at the next tick's status reply: within a tick (0.25 s) and a round trip, plus the
        # routine's wait for the CPU beside two hogs (tens of ms), and for the recording the 2000
        # bytes it may still write (50 ms); 1 s of room.
        assert 0 <= death_to_failure_s <= 1.0
    elif victim == "sclang":
        # Found at the first tick after sclang goes on (at most a tick, 0.25 s), or by the trial
        # in flight, whichever runs first; the same 1 s of room for the CPU.
        assert STOPPED_S <= death_to_failure_s <= STOPPED_S + 1.0
    else:
        # The watch sends a /sync every 0.25 s, on AppClock, and fails the session lostAfterS after
        # the last answer. That answer came up to 0.25 s (a watch period) before the kill, and the
        # script notes the kill's time after `kill -9` has returned (its fork and exec: a few ms,
        # 0.1 s allowed): so the failure comes at least lostAfterS - 0.35 s after that time (a
        # fresh clone's run: 2.996 s after it, lostAfterS 3). At most lostAfterS + 0.25 s, plus
        # the time its routine waits for the CPU (beside two CPU hogs at normal priority, tens of
        # ms); 1 s of room covers that with margin.
        assert lost_after_s - 0.35 <= death_to_failure_s <= lost_after_s + 1.0
    at_kill, at_over, later = (int(n) for n in run.lines("KF-ROWS")[0])
    # At most the trial whose store (after its /synced) crossed the kill; nothing after the failure
    # (the old session stored a trial every 0.4 s until the end).
    assert at_kill <= at_over <= at_kill + 1 and later == at_over, (at_kill, at_over, later)
    folder = root / "L1"
    assert len(read_csv(folder / "trials.csv")) == later
    session = read_csv(folder / "session.csv")
    assert session[-1]["event"] == "error" and REASONS[victim] in session[-1]["detail"], session
    events = [e["event"] for e in read_csv(folder / "01-forceStep" / "events.csv")]
    assert events[-1] == "lost" and "done" not in events and "estimate" not in events, events
    assert "the session failed" in run.output
    if victim == "failing":
        # The device's own part: the magnet off and the recording ended by the failure, at once.
        recording = readers.Session(folder / "01-forceStep" / "device.kfsession")
        assert recording.off_causes[-1:] == ["failure"], recording.off_causes
        assert "the simulated device failed (kfSimFail)" in run.output


FAILING = r"""
var study, session, path = @ROOT@ +/+ "F1/trials.csv";
study = FrictionStudy("failing", [
	FrictionStudyCondition.threshold(\forceStep, {
		FrictionThreshold.force(FrictionConstantStimuli([0.05, 0.1, 0.2], 10, seed: 3), 0.3, 0.15, 0.05, seed: 2)
	}, "Which interval held more friction?", [], 120, \keys, { |seed| FrictionObserver(0.1, 3.5, 0.02, seed: seed) })]);
session = study.run("F1", @ROOT@, s, simulated: FrictionStudySimParticipant(4, 2), windows: false);
while { File.exists(path).not } { 0.01.wait };
// trials.csv cannot be written from now on (a folder in its place: root writes any file).
("rm " ++ path.shellQuote ++ " && mkdir " ++ path.shellQuote).systemCmd;
while { session.isOver.not } { 0.05.wait };
1.wait;
s.sync;
"KF-STATE %\n".postf(session.state);
"KF-LEFT synths % slot %\n".postf(s.numSynths, FrictionDevice.at(s, 0));
"""


def test_a_failed_session_frees_what_it_started(jack):
    """trials.csv made unwritable mid-condition: the session fails with the reason, and leaves no
    synth (the experiment's stimulus, the listen synth, the audio recorder) and no device open."""
    root = paths.work_dir() / "study-failing"
    shutil.rmtree(root, ignore_errors=True)
    run = sclang.run_with_server(sclang.fill(FAILING, ROOT=sclang.sc_string(str(root))), jack, timeout=90,
                                 name="study-failing", server_options={"numOutputBusChannels": 4})
    assert run.lines("KF-STATE") == [["failed"]], run.output[-3000:]
    assert run.lines("KF-LEFT") == [["synths", "0", "slot", "nil"]], run.output[-3000:]
    session = read_csv(root / "F1" / "session.csv")
    assert session[-1]["event"] == "error" and "cannot write" in session[-1]["detail"], session


SILENT = r"""
var study, session, path = @ROOT@ +/+ "C1/trials.csv";
var rows = { if(File.exists(path)) { File.readAllString(path).split($\n).reject(_.isEmpty).size - 1 } { 0 } };
study = FrictionStudy("silent", [
	FrictionStudyCondition.threshold(\forceStep, {
		FrictionThreshold.force(FrictionConstantStimuli([0.3, 0.5], 20, seed: 3), 0.3, 2.5, 0.05, seed: 2)
	}, "Which interval held more friction?", [], 120, \keys, { |seed| FrictionObserver(0.1, 3.5, 0.02, seed: seed) })]);
session = study.run("C1", @ROOT@, s, simulated: FrictionStudySimParticipant(4, 2), windows: false);
// The first trial stored, the second starts: its first interval plays for 2.5 s from server.latency on.
while { rows.value < 1 } { 0.01.wait };
"KF-TIMEOUT %\n".postf(FrictionStudySession.clientTimeoutS);
// sclang falls silent (as a crashed or killed one would), its synths playing on in the server.
"kill -STOP %; sleep @STOPPED@; kill -CONT %".format(thisProcess.pid, thisProcess.pid).systemCmd;
while { session.isOver.not } { 0.05.wait };
"KF-STATE %\n".postf(session.state);
"""


def test_a_silent_client_turns_the_force_off(jack):
    """sclang stopped (SIGSTOP) for 4 s mid-threshold-condition, in a trial's first interval (2.5 s
    long), its stimulus synth holding the 0.3 N reference or a target: the server turns the magnet
    off once no heartbeat has come for clientTimeoutS (the off's cause "client" in the device
    recording), and records and drives nothing more until sclang is heard again (the old server
    held the force for as long as it ran)."""
    root = paths.work_dir() / "study-silent-client"
    shutil.rmtree(root, ignore_errors=True)
    stopped_s = 4
    run = sclang.run_with_server(sclang.fill(SILENT, ROOT=sclang.sc_string(str(root)), STOPPED=stopped_s), jack,
                                 timeout=90, name="study-silent-client", server_options={"numOutputBusChannels": 4})
    assert run.lines("KF-STATE") == [["failed"]], run.output[-3000:]  # it stood still (the test above)
    timeout_s = float(run.lines("KF-TIMEOUT")[0][0])
    recording = readers.Session(root / "C1" / "01-forceStep" / "device.kfsession")
    assert "client" in recording.off_causes, recording.off_causes
    off_s = recording.offs[recording.off_causes.index("client")]
    frames, reports = recording.frames, recording.reports
    before = frames[(frames[:, 0] > off_s - 1.0) & (frames[:, 0] < off_s)]
    # The magnet was driven up to the client's off (the stimulus played on while sclang was
    # stopped), at the reference or more, above the 0.14 N of the magnet off: every frame of the
    # second before it, and no other off between the last of them and it. (How many frames that
    # second holds is the audio thread's pace, not the watch's: 890 against the plugin under ASan.)
    assert len(before) > 0 and before[:, 3].min() >= 0.3 - 1e-6, before[:, 3].min() if len(before) else None
    assert not [t for t in recording.offs if before[-1, 0] < t < off_s], (before[-1, 0], off_s, recording.offs)
    # Nothing recorded after the off until sclang was heard again. The stop came at most a
    # heartbeat period (timeout / 4) after the last heartbeat, the off timeout after it, and the
    # first heartbeat after the stop ends it: so the quiet lasts at least stopped - timeout s.
    after = np.concatenate([frames[frames[:, 0] > off_s, 0], reports[reports[:, 0] > off_s, 0]])
    quiet_s = (after.min() if len(after) else np.inf) - off_s
    print(f"KF-FIGURE study_silent_client_quiet_s {quiet_s:.3f}")
    assert quiet_s >= stopped_s - timeout_s - 0.05, quiet_s


ORPHANED = r"""
var study, session, path = @ROOT@ +/+ "K1/trials.csv";
var rows = { if(File.exists(path)) { File.readAllString(path).split($\n).reject(_.isEmpty).size - 1 } { 0 } };
FrictionStudySession.clientTimeoutS = @TIMEOUT@;
study = FrictionStudy("orphaned", [
	FrictionStudyCondition.threshold(\forceStep, {
		FrictionThreshold.force(FrictionConstantStimuli([0.3, 0.5], 20, seed: 3), 0.3, 0.15, 0.05, seed: 2)
	}, "Which interval held more friction?", [], 120, \keys, { |seed| FrictionObserver(0.1, 3.5, 0.02, seed: seed) })]);
session = study.run("K1", @ROOT@, s, simulated: FrictionStudySimParticipant(4, 2), windows: false);
while { rows.value < 2 } { 0.01.wait };
File.use(@PIDS@, "w", { |f| f.write("% %\n".format(thisProcess.pid, s.pid)) });
120.wait;
"KF-NOT-KILLED\n".post;
"""
ORPHAN_TIMEOUT_S = 1.0


def test_a_killed_client_leaves_a_server_that_stops_the_force_and_the_recordings(jack):
    """kill -9 of sclang mid-threshold-condition, its server left running (as after a crash of the
    client alone): once no heartbeat has come for clientTimeoutS the magnet is off (cause "client"),
    and neither the device recording nor the condition's audio.wav grows any more (SC's Recorder
    went on writing audio.wav for as long as the server ran: 21 s). An orderly /quit of the server
    then leaves audio.wav a whole WAV holding what was recorded up to the silence."""
    root = paths.work_dir() / "study-orphaned"
    shutil.rmtree(root, ignore_errors=True)
    condition = root / "K1" / "01-forceStep"
    files = [condition / "audio.wav", condition / "device.kfsession"]
    sizes = {}

    def orphaned(scsynth_pid, quit):
        killed_s = time.monotonic()
        # The silence is seen within the timeout plus a heartbeat period (timeout / 4) after the
        # kill; the audio's last half buffer (0.68 s at 48 kHz) was written by the disk thread
        # before the pause could hold it. 1.5 s more is room for both.
        time.sleep(max(0.0, killed_s + ORPHAN_TIMEOUT_S * 1.25 + 1.5 - time.monotonic()))
        sizes["silent"] = [f.stat().st_size for f in files]
        # 2.5 s later: a recording still running would have grown by 3 of DiskOut's half buffers
        # and by 100 kB of device recording.
        time.sleep(2.5)
        sizes["later"] = [f.stat().st_size for f in files]
        sizes["alive"] = procs.pid_alive(scsynth_pid)
        quit()
        sizes["quit"] = procs.wait_pid_gone(scsynth_pid, 10.0)

    code = sclang.fill(ORPHANED, ROOT=sclang.sc_string(str(root)), TIMEOUT=ORPHAN_TIMEOUT_S,
                       PIDS=sclang.sc_string(str(sclang.pids_file("study-orphaned"))))
    run = sclang.run_and_kill(code, jack, lambda: True, name="study-orphaned", orphaned=orphaned,
                              server_options={"numOutputBusChannels": 4})
    assert "KF-NOT-KILLED" not in run.output
    assert sizes["alive"] and sizes["quit"], sizes  # the server played on, then quit when told
    print(f"KF-FIGURE study_orphaned_sizes {sizes}")
    assert sizes["later"] == sizes["silent"], sizes
    recording = readers.Session(files[1])
    assert "client" in recording.off_causes, recording.off_causes
    off_s = recording.offs[recording.off_causes.index("client")]
    frames, reports = recording.frames, recording.reports
    assert not len(frames[frames[:, 0] > off_s]) and not len(reports[reports[:, 0] > off_s]), off_s
    audio, rate = soundfile.read(str(files[0]), always_2d=True)
    assert audio.shape[1] == 2 and audio.shape[0] > 0 and np.isfinite(audio).all(), audio.shape
