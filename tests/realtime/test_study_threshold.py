"""A threshold condition in a FrictionStudy: the study calls FrictionThreshold's run(device,
answers, onTrial, onEnd, out) inside its Routine, a FrictionObserver answering for the simulated
participant; each trial goes into trials.csv as it comes; start, the experiment, the observer,
each trial, the end and the estimate are logged; its questions follow. The report fits the trials
(kfstudy.psychometric) and draws them beside the observer's known function."""
import json
import shutil

import numpy as np

from kfharness import paths, sclang, bids_check
from kfstudy import psychometric, report
from kfstudy.session_folder import read_csv

LEVELS, REPEATS, THRESHOLD = [0.05, 0.1, 0.2], 4, 0.1

SCRIPT = r"""
var study, session, rows = [], path = @ROOT@ +/+ "T1/trials.csv";
study = FrictionStudy("threshold", [
	FrictionStudyCondition.threshold(\forceStep, {
		FrictionThreshold.force(FrictionConstantStimuli(@LEVELS@, @REPEATS@, seed: 3), 0.3, 0.15, 0.05, seed: 2)
	}, "Which interval held more friction?", [FrictionStudyQuestion.text(\how, "How did you decide?")], 60, \keys,
	{ |seed| FrictionObserver(@THRESHOLD@, 3.5, 0.02, seed: seed) })]);
session = study.run("T1", @ROOT@, s, simulated: FrictionStudySimParticipant(4, 2), windows: false);
// What the folder holds while the trials run (a trial every 0.4 s), looked at every 0.05 s.
while { session.isOver.not } {
	if(File.exists(path)) { rows = rows.add(File.readAllString(path).split($\n).reject(_.isEmpty).size - 1) };
	0.05.wait
};
"KF-ROWS %\n".postf(rows.asSet.asArray.sort.join(" "));
"KF-STATE %\n".postf(session.state);
"""


def test_a_threshold_condition_writes_its_trials_and_the_report_fits_them(jack):
    root = paths.work_dir() / "study-threshold"
    shutil.rmtree(root, ignore_errors=True)
    count = len(LEVELS) * REPEATS
    run = sclang.require_ok(sclang.run_with_server(
        sclang.fill(SCRIPT, ROOT=sclang.sc_string(str(root)), LEVELS=LEVELS, REPEATS=REPEATS, THRESHOLD=THRESHOLD),
        jack, timeout=60, name="study-threshold", server_options={"numOutputBusChannels": 4}))
    assert run.lines("KF-STATE") == [["finished"]], run.output[-3000:]
    # Written and flushed as each trial comes: the folder held every count on the way.
    seen = [int(n) for n in run.lines("KF-ROWS")[0]]
    assert seen == list(range(0, count + 1)) or seen == list(range(1, count + 1)), seen
    folder = root / "T1"
    trials = read_csv(folder / "trials.csv")
    assert [t["trial"] for t in trials] == [str(n) for n in range(1, count + 1)]
    assert sorted(float(t["level"]) for t in trials) == sorted(LEVELS * REPEATS)
    assert all(t["condition"] == "forceStep" and t["participant"] == "T1" for t in trials)
    assert [t["correct"] == "true" for t in trials] == [t["answer"] == t["target"] for t in trials]
    events = read_csv(folder / "01-forceStep" / "events.csv")
    names = [e["event"] for e in events]
    assert names == ["prepare", "recordDevice", "experiment", "observer", "recordAudio", "start"] + [
        "trial"] * count + ["done", "estimate", "answer", "end"], names
    detail = {e["event"]: e["detail"] for e in events}
    assert json.loads(detail["experiment"])["kind"] == "force"
    assert json.loads(detail["observer"])["threshold"] == THRESHOLD
    estimate = json.loads(detail["estimate"])
    right = sum(t["correct"] == "true" for t in trials)
    assert [(a["question"], a["source"], a["answer"]) for a in read_csv(folder / "answers.csv")] == [
        ("how", "simulated", f"simulated: {right} of {count} trials answered right by its model observer")]
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["study"]["conditions"][0]["threshold"] is True

    # The report fits these trials (psychometric.fit, as on its own) and draws them.
    summary = report.write_report(root, root / "report")
    (fit,) = summary["thresholds"].to_dict("records")
    own = psychometric.fit([float(t["level"]) for t in trials], [t["correct"] == "true" for t in trials])
    assert fit["threshold"] == own["threshold"] and fit["trials"] == count
    assert fit["observer_threshold"] == THRESHOLD and fit["unit"] == "N"
    assert fit["estimate"] == estimate["threshold"]
    md = (root / "report" / "report.md").read_text()
    assert f"| forceStep | {count} | {own['threshold']:.4g} N |" in md
    assert "(T1-forceStep-psychometric.png)" in md
    from PIL import Image
    with Image.open(root / "report" / "T1-forceStep-psychometric.png") as image:
        assert np.asarray(image.convert("L")).std() > 10
    assert [r["condition"] for r in read_csv(root / "report" / "thresholds.csv")] == ["forceStep"]

    # The same data as BIDS behavioural data, read with pandas, each column against its sidecar.
    tables = bids_check.read_checked(root / "report" / "bids")
    beh = tables["sub-T1/beh/sub-T1_task-threshold_acq-trials_beh.tsv"]
    assert list(beh["trial"]) == [t["trial"] for t in trials] and set(beh["unit"]) == {"N"}
    assert list(beh["level"].astype(float)) == [float(t["level"]) for t in trials]
    assert set(beh["experiment"]) == {"force"} and set(beh["procedure"]) == {"constantStimuli"}
    assert tables["derivatives/kfstudy/trials.tsv"].equals(beh)
    counts = tables["derivatives/kfstudy/sub-T1_cond-forceStep_counts.tsv"].astype(float)
    assert list(counts["level"]) == sorted(set(LEVELS)) and set(counts["n_total"]) == {REPEATS}
    assert counts["n_correct"].sum() == right
    assert list(tables["participants.tsv"]["participant_id"]) == ["sub-T1"]
    assert json.loads((root / "report" / "bids" / "dataset_description.json").read_text())["BIDSVersion"] == "1.9.0"


REFUSALS = r"""
var root = @ROOT@, sim = FrictionStudySimParticipant(4, 2), refused = { |tag, make|
	try {
		FrictionStudy("stimuli", [FrictionStudyCondition(\first, (mapping: \mapping1), "Explore.", [], 60),
			FrictionStudyCondition.threshold(\forceStep, make, "Which?", [], 60, \keys,
				{ |seed| FrictionObserver(0.1, seed: seed) })]).run(tag.asString, root, s, simulated: sim, windows: false);
		"KF-ACCEPTED %\n".postf(tag)
	} { |e| "KF-REFUSED % %\n".postf(tag, e.errorString) }
};
refused.(\unrenderable, { FrictionThreshold.force(FrictionConstantStimuli([0.05, 2]), 0.3) });
refused.(\negativeBase, { FrictionThreshold.force(FrictionStaircase(0.1), -0.3) });
refused.(\nanInterval, { FrictionThreshold.force(FrictionStaircase(0.1), 0.3, 0/0) });
refused.(\notAnExperiment, { FrictionStaircase(0.1) });
refused.(\notAProcedure, { FrictionThreshold.force((next: 0.1), 0.3) });
"""


def test_stimuli_the_device_cannot_render_are_refused_before_the_session_starts(jack):
    """A threshold condition whose levels or base force lie outside the (simulated) device's
    0.14-1.4 N, second in the order: the session is refused when it is run, with the reason, before
    its first condition (nothing written but the empty folder). A NaN interval, an experiment that
    is not a FrictionThreshold, a procedure that is not a FrictionProcedure: refused when the study
    is made."""
    root = paths.work_dir() / "study-refused-stimuli"
    shutil.rmtree(root, ignore_errors=True)
    run = sclang.require_ok(sclang.run_with_server(
        sclang.fill(REFUSALS, ROOT=sclang.sc_string(str(root))), jack, timeout=60, name="study-refused-stimuli",
        server_options={"numOutputBusChannels": 4}))
    assert not run.lines("KF-ACCEPTED"), run.output[-3000:]
    refused = {fields[0]: " ".join(fields[1:]) for fields in run.lines("KF-REFUSED")}
    expected = {
        "unrenderable": "condition forceStep: FrictionThreshold.force: 2.3 N (the reference 0.3 N + the level 2) "
                        "is outside the 0.14 N to 1.4 N that the simulated device renders",
        "negativeBase": "-0.3 N (the reference -0.3 N + the level 0)",
        "nanInterval": "intervalS must be a finite number",
        "notAnExperiment": "makeExperiment must give a FrictionThreshold, got a FrictionStaircase",
        "notAProcedure": "procedure must be a FrictionProcedure",
    }
    for tag, words in expected.items():
        assert words in refused.get(tag, ""), (tag, refused.get(tag), run.output[-3000:])
    for tag in expected:
        written = list((root / tag).iterdir()) if (root / tag).exists() else []
        assert not written, f"{tag}: the refused session wrote {written}"
