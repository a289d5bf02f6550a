"""A FrictionStudy session on a realtime server: bad input refused before anything starts, and a
session killed mid-condition (scsynth and sclang, by pid) that loses nothing and resumes from
sclang at the condition it was in."""
import json
import shutil
import subprocess
import time

import numpy as np

from kfharness import paths, sclang
from kfstudy import readers, report
from kfstudy.session_folder import read_csv

# Two conditions of mapping 1 (its 6 mm), each explored for 2.5 s by a simulated participant
# (explore-s: 6 speed steps of 0.42 s), and a free-text and a rating question after each.
STUDY = r"""
var questions = [FrictionStudyQuestion.text(\say, "Describe it."), FrictionStudyQuestion.rating(\hold, "How held?", 1, 5)];
~study = FrictionStudy("resume test", [
	FrictionStudyCondition(\first, (mapping: \mapping1, friction: false), "Explore.", questions, 60),
	FrictionStudyCondition(\second, (mapping: \mapping1, friction: true), "Explore again.", questions, 60)]);
"""


def test_bad_input_is_refused_before_anything_starts(jack):
    root = paths.work_dir() / "study-refusals"
    shutil.rmtree(root, ignore_errors=True)
    (root / "P1").mkdir(parents=True)
    code = sclang.fill(r"""
var root = @ROOT@, sim = FrictionStudySimParticipant(1, 2), refused = { |tag, f|
	try { f.value; "KF-ACCEPTED %\n".postf(tag) } { |e| "KF-REFUSED % %\n".postf(tag, e.errorString) }
};
""" + STUDY + r"""
refused.(\noConditions, { FrictionStudy("empty", []) });
refused.(\unknownParameter, { FrictionStudyCondition(\a, (mapping: \mapping1, frictionn: true)) });
refused.(\badMapping, { FrictionStudyCondition(\a, (mapping: -3)) });
refused.(\unwritable, { ~study.run("P2", "/proc/kf-study-cannot-write", s, simulated: sim, windows: false) });
refused.(\reused, { ~study.run("P1", root, s, simulated: sim, windows: false) });
refused.(\channels, { ~study.run("P3", root, s, simulated: sim, windows: false, experimenterOut: 2) });
refused.(\overlap, { ~study.run("P3", root, s, simulated: sim, windows: false, experimenterOut: 1) });
refused.(\badCode, { ~study.run("P 3/..", root, s, simulated: sim, windows: false) });
refused.(\noDevice, { ~study.run("P3", root, s, windows: false) });
""", ROOT=sclang.sc_string(str(root)))
    run = sclang.require_ok(sclang.run_with_server(code, jack, timeout=60, name="study-refusals"))
    refused = {fields[0]: " ".join(fields[1:]) for fields in run.lines("KF-REFUSED")}
    assert not run.lines("KF-ACCEPTED"), run.lines("KF-ACCEPTED")
    expected = {
        "noConditions": "needs at least one condition",
        "unknownParameter": "unknown scene parameter 'frictionn'",
        "badMapping": "samplesPerMm",
        "unwritable": "cannot be written",
        "reused": "participant code P1 already has a session",
        "channels": "the server has 2 output channels",
        "overlap": "overlap",
        "badCode": "participant code must be letters",
        "noDevice": "give either device",
    }
    for tag, words in expected.items():
        assert tag in refused and words in refused[tag], (tag, refused.get(tag), run.output[-3000:])
    # Nothing was written for the refused sessions: only the folder the test made is there.
    assert sorted(p.name for p in root.iterdir()) == ["P1"]
    assert not any((root / "P1").iterdir())


def events_of(folder):
    return [row["event"] for row in read_csv(folder / "events.csv")]


def test_a_killed_session_resumes_with_nothing_lost(jack):
    root = paths.work_dir() / "study-resume"
    session = root / "P7"
    shutil.rmtree(root, ignore_errors=True)
    # Run 1: the session starts; the test kills scsynth and sclang once the second condition runs.
    first = STUDY + sclang.fill(r"""
~session = ~study.run("P7", @ROOT@, s, 0, 11, simulated: FrictionStudySimParticipant(3, 2.5), windows: false,
	experimenterOut: 2);
File.use(@PIDS@, "w", { |f| f.write("% %\n".format(thisProcess.pid, s.pid)) });
while { ~session.isOver.not } { 0.1.wait };
"KF-NOT-KILLED\n".post;
""", ROOT=sclang.sc_string(str(root)), PIDS=sclang.sc_string(str(sclang.pids_file("study-run"))))
    second_events = session / "02-second" / "events.csv"
    started = {}

    def mid_condition():
        # 0.6 s into the second condition's 2.5 s of exploring (1.9 s to spare for a slow wake-up).
        if "at" not in started and second_events.exists() and "start" in second_events.read_text():
            started["at"] = time.monotonic()
        return "at" in started and time.monotonic() - started["at"] >= 0.6

    run = sclang.run_and_kill(first, jack, mid_condition, name="study-run",
                              server_options={"numOutputBusChannels": 4})
    assert "KF-NOT-KILLED" not in run.output

    # What the kill left: the manifest, the first condition whole with its answers, the second begun.
    manifest = json.loads((session / "manifest.json").read_text())
    assert manifest["participant"] == "P7" and manifest["seed"] == 11 and manifest["order"] == ["first", "second"]
    assert manifest["sampleRateHz"] == jack.sample_rate and manifest["device"]["kind"] == "sim"
    assert manifest["device"]["specs"]["tactileLatencyS"] == 0.0024 and manifest["version"] != "unknown"
    # What made the data: the commit installed (the tests install from this tree), SuperCollider,
    # the report's python3 and the time zone, as this machine has them.
    head = subprocess.run(["git", "-C", str(paths.REPO_DIR), "rev-parse", "HEAD"], capture_output=True, text=True)
    provenance = manifest["provenance"]
    assert provenance["commit"] == (head.stdout.strip() if head.returncode == 0 else "unknown"), provenance
    assert provenance["supercollider"].startswith("3.") and provenance["platform"] == "linux"
    assert provenance["python"] == subprocess.run(["/usr/bin/python3", "--version"], capture_output=True,
                                                  text=True).stdout.replace("Python", "").strip()
    assert provenance["timeZone"] == time.strftime("%z")
    answers_before = (session / "answers.csv").read_bytes()
    rows = read_csv(session / "answers.csv")
    assert [(r["condition"], r["question"]) for r in rows] == [("first", "say"), ("first", "hold")]
    assert events_of(session / "01-first")[-1] == "end"
    killed = events_of(session / "02-second")
    assert "start" in killed and "end" not in killed, killed
    killed_recording = (session / "02-second" / "device.kfsession").read_text()
    # Recorded from before the start line: at least 0.6 s of reports at 125 Hz (75), less a margin.
    assert killed_recording.count("\nR ") > 40, "the killed condition's recording lost its lines"

    # The crash also cut answers.csv's last row inside its answer (a full disk, a power cut).
    answers_cut = answers_before[:-20]
    (session / "answers.csv").write_bytes(answers_cut)

    # Run 2: resume from sclang; the second condition runs again, the first is kept as it was.
    second = STUDY + sclang.fill(r"""
~session = ~study.resume(@SESSION@, s, simulated: FrictionStudySimParticipant(3, 2.5), windows: false);
while { ~session.isOver.not } { 0.1.wait };
"KF-RESUMED % %\n".postf(~session.state, ~session.position);
""", SESSION=sclang.sc_string(str(session)))
    run = sclang.require_ok(sclang.run_with_server(second, jack, timeout=120, name="study-resume",
                                                   server_options={"numOutputBusChannels": 4}))
    assert run.lines("KF-RESUMED") == [["finished", "2"]], run.output[-3000:]
    assert (session / "answers.csv").read_bytes().startswith(answers_cut + b"\n")
    damaged = []
    rows = read_csv(session / "answers.csv", damaged)
    # The cut row is skipped and named; every other row, before and after it, is read whole.
    assert [(r["condition"], r["question"], r["attempt"]) for r in rows] == [
        ("first", "say", "1"), ("second", "say", "2"), ("second", "hold", "2")]
    assert [d.line for d in damaged] == [3], damaged
    # The killed attempt is kept whole; the second attempt ran beside it.
    assert events_of(session / "02-second") == killed
    assert (session / "02-second" / "device.kfsession").read_text() == killed_recording
    assert events_of(session / "02-second-attempt2")[-1] == "end"
    log = [row["event"] for row in read_csv(session / "session.csv")]
    assert log == ["start", "resume", "finish"], log
    for folder in ("01-first", "02-second-attempt2"):
        data, rate = readers.read_wav(session / folder / "audio.wav")
        assert rate == jack.sample_rate and data.shape[1] == 2 and len(data) > rate, folder
        assert readers.Session(session / folder / "device.kfsession").frames.shape[0] > 1000, folder

    # The report names the damaged row and is made for the other participants when one's files
    # cannot be read: P8's manifest and P9's recording get garbage bytes.
    for code, damage in (("P8", "manifest.json"), ("P9", "01-first/device.kfsession")):
        shutil.copytree(session, root / code)
        manifest = json.loads((root / code / "manifest.json").read_text())
        (root / code / "manifest.json").write_text(json.dumps(dict(manifest, participant=code)))
        target = root / code / damage
        target.write_bytes(target.read_bytes()[:40] + b"\xff\xfe garbage" + target.read_bytes()[40:])
    summary = report.write_report(root, root / "report")
    text = (root / "report" / "report.md").read_text()
    assert [s.participant for s in summary["sessions"]] == ["P7", "P9"]
    assert "`P8` cannot be read" in text and "## Participant P9" in text and "answers.csv line 3" in text
    p9 = text.split("## Participant P9")[1]
    assert "Not reported: its files cannot be read" in p9 and "01-first/device.kfsession: not UTF-8" in p9 and "Not reported" not in text.split("## Participant P7")[1].split("## ")[0]
    assert set(summary["conditions"].participant) == {"P7"}


# A person's session on a replayed recording whose puck's right button goes down 2.0 s after the
# device opens (bit 2 of the reports' buttons, 0.2 s long); then a simulated participant's session
# that the experimenter aborts 0.5 s into its second condition.
DONE_AND_ABORT = r"""
var root = @ROOT@, device, session, sim, aborted, served = Condition(), counted = Condition(), synths;
~study = FrictionStudy("button and abort", [
	FrictionStudyCondition(\first, (mapping: \mapping1), "Explore; press a button when done.",
		[FrictionStudyQuestion.text(\say, "Describe it.")], 20),
	FrictionStudyCondition(\second, (mapping: \mapping2), "Explore again.", [], 20)]);
device = FrictionDevice.replay(s, @RECORDING@, 0, (loop: true));
s.sync;
session = ~study.run("B1", root, s, device: device, windows: false, experimenterOut: 2);
while { session.state != \questions } { 0.05.wait };
session.answer("pressed the right button");
while { session.state != \running } { 0.05.wait };
session.abort;  // the experimenter: the second condition has no use here
while { session.isOver.not } { 0.05.wait };
"KF-BUTTON %\n".postf(session.state);
device.close;
// Its participant explores each condition 4 s: the abort below, after 0.5 s of the server's audio,
// must come first (a 1.5 s participant finished first once beside a busy machine: the audio ran
// at 45 % of the wall clock there, so 0.5 s of it takes about 1.1 s; 4 s leaves room).
aborted = ~study.run("A1", root, s, simulated: FrictionStudySimParticipant(2, 4), windows: false,
	experimenterOut: 2);
while { aborted.position < 1 or: { aborted.state != \running } } { 0.05.wait };
// 0.5 s into the condition on the server's clock (its audio.wav's) as well as sclang's: without
// realtime scheduling the server's falls behind (a JACK cycle that comes late is an xrun, and
// the dummy driver starts its clock again from then: 0.38 s of audio in 0.5 s seen here).
{ Line.kr(0, 0, 0.5, doneAction: 2); DC.ar(0) }.play.onFree { served.test = true; served.signal };
served.wait;
while { aborted.elapsedS < 0.5 } { 0.05.wait };
aborted.abort;
while { aborted.isOver.not } { 0.05.wait };
// The server's count of synths, asked after the session's frees (the sync), not its 0.7 s poll's.
s.sync;
OSCFunc({ |msg| synths = msg[3]; counted.test = true; counted.signal }, '/status.reply', s.addr).oneShot;
s.sendMsg('/status');
counted.wait;
"KF-ABORTED % % synths\n".postf(aborted.state, synths);
"""


def test_done_from_a_puck_button_and_the_experimenters_abort(jack):
    root = paths.work_dir() / "study-button-abort"
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    recording = root / "presses.kfs"
    lines = ["kf-session 1 countMm=0.021 updateRateHz=125"]
    for i in range(1, 1000):
        t = i * 0.008
        lines.append(f"R {t:.3f} {t:.3f} 1 0 {2 if 2.0 <= t % 4 < 2.2 else 0} 0")
    recording.write_text("\n".join(lines) + "\n")
    run = sclang.require_ok(sclang.run_with_server(
        sclang.fill(DONE_AND_ABORT, ROOT=sclang.sc_string(str(root)), RECORDING=sclang.sc_string(str(recording))),
        jack, timeout=90, name="study-button-abort", server_options={"numOutputBusChannels": 4}))
    assert run.lines("KF-BUTTON") == [["aborted"]], run.output[-3000:]

    # The button ended the first condition: its "done" says so, at a press, a block and a status
    # poll late at most (0.03 s measured, 0.5 s allowed on a busy machine). The replay, looped,
    # presses 2.0 s into every 4 s: the press the session meets is the first after its set-up,
    # which took a few ms alone, 0.113 s in a sanitized run beside other tests and more than 2.2 s
    # beside a second test command (fresh clone 66, when the one press was 2.0 s after the open).
    # done's time counts from the prepare line: placed on the device's clock by its recording,
    # which started before the recordDevice line (the record command is answered first) and after
    # the prepare line, and whose first report came within a report period (8 ms) and a pump of
    # its start.
    folder = root / "B1" / "01-first"
    events = read_csv(folder / "events.csv")
    done = [e for e in events if e["event"] == "done"]
    assert [e["detail"] for e in done] == ["button"], events
    recording = readers.Session(folder / "device.kfsession")
    first_s = recording.reports[0, 0]
    pressed = (recording.reports[:, 4].astype(int) & 2) != 0
    onsets_s = recording.reports[pressed & ~np.concatenate([[False], pressed[:-1]]), 0]
    record_s = float(next(e["timeS"] for e in events if e["event"] == "recordDevice"))
    done_s = float(done[0]["timeS"])
    earliest, latest = done_s + first_s - record_s - 0.010, done_s + first_s  # on the device's clock
    assert any(latest >= p and earliest <= p + 0.5 for p in onsets_s), (earliest, latest, onsets_s, events)
    assert [e["event"] for e in events][-2:] == ["answer", "end"]

    # The abort: the session ends at once, what was written is kept and the abort logged, in the
    # condition's events and the session's log; nothing is left playing on the server.
    assert run.lines("KF-ABORTED") == [["aborted", "0", "synths"]], run.output[-3000:]
    session = root / "A1"
    log = read_csv(session / "session.csv")
    assert [(r["event"], r["detail"]) for r in log] == [("start", ""), ("abort", "second")], log
    assert events_of(session / "01-first")[-1] == "end"
    second = events_of(session / "02-second")
    assert second[second.index("start"):] == ["start", "abort", "coverage", "coverageMap"], second
    assert [(r["condition"], r["question"]) for r in read_csv(session / "answers.csv")] == [("first", "say")]
    # The aborted condition's recordings are kept: the device's (0.5 s and more of reports at
    # 125 Hz: 62, less a margin), the audio as long as the condition ran (0.5 s and more of the
    # server's clock: the script waited for it).
    recording = readers.Session(session / "02-second" / "device.kfsession")
    assert len(recording.reports) > 40
    data, rate = readers.read_wav(session / "02-second" / "audio.wav")
    assert len(data) > 0.5 * rate
    assert not (session / "03-second").exists() and sorted(p.name for p in session.iterdir()) == [
        "01-first", "02-second", "answers.csv", "manifest.json", "session.csv"]
