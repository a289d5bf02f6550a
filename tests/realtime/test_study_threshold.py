"""A threshold condition in a FrictionStudy: the study calls the experiment's run(device,
answers, onTrial, onEnd, out) inside its Routine, writes each trial into trials.csv as it comes,
logs start, each trial, the end and the estimate, then asks its questions. The experiment here is
a stand-in written in this test (an Event with run), keeping to the interface of
FrictionThreshold, with a model observer that answers correctly from a level on."""
import csv
import json
import shutil

from kfharness import paths, sclang, study_report

SCRIPT = r"""
var makeExperiment, makeObserver, study, session;
// The stand-in: five trials at falling levels, each an Event as FrictionThreshold passes them.
makeExperiment = {
	(run: { |self, device, answers, onTrial, onEnd, out|
		var t0 = Main.elapsedTime, estimate;
		if(device.isKindOf(FrictionDevice).not or: { device.isOpen.not }) { Error("no device").throw };
		[0.4, 0.2, 0.1, 0.05, 0.025].do { |level, i|
			var target = 1 + (i % 2), correct = answers.answer(level), trial;
			0.1.wait;
			trial = (trial: i + 1, level: level, target: target, answer: if(correct) { target } { 3 - target },
				correct: correct, startS: Main.elapsedTime - t0 - 0.1, interval1S: Main.elapsedTime - t0 - 0.1,
				interval2S: Main.elapsedTime - t0 - 0.05, answerS: Main.elapsedTime - t0);
			onTrial.value(trial);
			// Written and flushed as each trial comes: the file holds it when onTrial returns.
			"KF-ROWS %".format(File.readAllString(@ROOT@ +/+ "T1/trials.csv").split($\n).reject(_.isEmpty).size - 1)
				.postln;
		};
		estimate = (threshold: 0.075, sd: 0.02);
		onEnd.value(estimate);
		estimate
	})
};
// The model observer's stand-in: correct from 0.1 on, whatever its seed.
makeObserver = { |seed| (seed: seed, answer: { |self, level| level >= 0.1 }) };
study = FrictionStudy("threshold", [
	FrictionStudyCondition.threshold(\forceStep, makeExperiment, "Which interval held more friction?",
		[FrictionStudyQuestion.text(\how, "How did you decide?")], 60, \keys, makeObserver)]);
session = study.run("T1", @ROOT@, s, simulated: FrictionStudySimParticipant(4, 2), windows: false);
while { session.isOver.not } { 0.1.wait };
"KF-STATE %".format(session.state).postln;
"""


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_threshold_condition_writes_its_trials(jack):
    root = paths.work_dir() / "study-threshold"
    shutil.rmtree(root, ignore_errors=True)
    run = sclang.require_ok(sclang.run_with_server(sclang.fill(SCRIPT, ROOT=sclang.sc_string(str(root))), jack,
                                                   timeout=60, name="study-threshold",
                                                   server_options={"numOutputBusChannels": 4}))
    assert run.lines("KF-STATE") == [["finished"]], run.output[-3000:]
    assert run.lines("KF-ROWS") == [[str(n)] for n in range(1, 6)]
    folder = root / "T1"
    trials = rows(folder / "trials.csv")
    assert [(t["trial"], t["level"], t["correct"]) for t in trials] == [
        ("1", "0.4", "true"), ("2", "0.2", "true"), ("3", "0.1", "true"), ("4", "0.05", "false"),
        ("5", "0.025", "false")]
    assert all(t["condition"] == "forceStep" and t["participant"] == "T1" for t in trials)
    assert [t["answer"] == t["target"] for t in trials] == [True, True, True, False, False]
    events = rows(folder / "01-forceStep" / "events.csv")
    names = [e["event"] for e in events]
    assert names == ["prepare", "recordDevice", "recordAudio", "start"] + ["trial"] * 5 + [
        "done", "estimate", "answer", "end"], names
    estimate = json.loads([e["detail"] for e in events if e["event"] == "estimate"][0])
    assert estimate == {"threshold": 0.075, "sd": 0.02}
    assert [(a["question"], a["source"]) for a in rows(folder / "answers.csv")] == [("how", "simulated")]
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["study"]["conditions"][0]["threshold"] is True
    # The report takes the session; its threshold section is the fit's (kfstudy.psychometric).
    summary = study_report.write_report(root, root / "report")
    assert len(summary["sessions"]) == 1
    assert "Threshold" in (root / "report" / "report.md").read_text()
