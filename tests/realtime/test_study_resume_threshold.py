"""A threshold condition killed after k trials and resumed continues its procedure (issue 42,
item 3): on a realtime server, scsynth and sclang are killed by pid once trials.csv holds a few
trials, and the stored last row is cut as a crash would leave it. The resume refuses the study
changed (fewer trials), then goes on: the staircase and the simulated participant's observer pick
up from the trials stored, so the levels and the estimate are those of the same seeded observer
run straight through; the trials are numbered on, session.csv's times count on, and the report
and the BIDS tables take exactly the trials the procedure used, saying how the attempts joined."""
import json
import shutil

import numpy as np

from kfharness import paths, sclang
from kfstudy import bids, psychometric, report
from kfstudy.session_folder import read_csv, sessions

# 0.4 s a trial (two 0.15 s intervals, 0.05 s gaps); the staircase ends at 8 reversals or
# MAX_TRIALS. maxLevel keeps the target (0.3 N + level) within the simulated device's 1.4 N.
MAX_TRIALS = 28
STUDY = r"""
~study = { |maxTrials| FrictionStudy("threshold resume", [
	FrictionStudyCondition.threshold(\forceStep, {
		FrictionThreshold.force(FrictionStaircase(0.4, 2, [0.2, 0.1, 0.05], \log, 8, maxTrials, maxLevel: 0.8),
			0.3, 0.15, 0.05, seed: 2)
	}, "Which interval held more friction?", [], 120, \keys, { |seed| FrictionObserver(0.1, 3.5, 0.02, seed: seed) })])
};
"""
SIM = "FrictionStudySimParticipant(4, 2)"
KILL_AFTER = 6  # trials stored


def test_a_resumed_threshold_condition_continues_its_procedure(jack):
    root = paths.work_dir() / "study-resume-threshold"
    session = root / "R1"
    shutil.rmtree(root, ignore_errors=True)
    first = STUDY + sclang.fill(r"""
~session = ~study.(@MAX@).run("R1", @ROOT@, s, simulated: @SIM@, windows: false, experimenterOut: 2);
File.use(@PIDS@, "w", { |f| f.write("% %\n".format(thisProcess.pid, s.pid)) });
while { ~session.isOver.not } { 0.1.wait };
"KF-NOT-KILLED\n".post;
""", MAX=MAX_TRIALS, ROOT=sclang.sc_string(str(root)), SIM=SIM,
                                PIDS=sclang.sc_string(str(sclang.pids_file("study-threshold-run"))))
    trials_csv = session / "trials.csv"
    run = sclang.run_and_kill(first, jack, lambda: trials_csv.exists() and len(read_csv(trials_csv)) >= KILL_AFTER,
                              name="study-threshold-run", server_options={"numOutputBusChannels": 4})
    assert "KF-NOT-KILLED" not in run.output
    stored = read_csv(trials_csv)
    k = len(stored)
    assert KILL_AFTER <= k < MAX_TRIALS - 4, k
    # The crash cut the last trial's row: the procedure goes on from the k - 1 whole ones.
    trials_csv.write_bytes(trials_csv.read_bytes()[:-15])
    session_times = [float(r["timeS"]) for r in read_csv(session / "session.csv")]

    second = sclang.fill(r"""
var straight = FrictionStaircase(0.4, 2, [0.2, 0.1, 0.05], \log, 8, @MAX@, maxLevel: 0.8), estimate;
""", MAX=MAX_TRIALS) + STUDY + sclang.fill(r"""
try { ~study.(5).resume(@SESSION@, s, simulated: @SIM@, windows: false) } { |e|
	"KF-REFUSED %\n".postf(e.errorString.replace("\n", " | ")) };
~session = ~study.(@MAX@).resume(@SESSION@, s, simulated: @SIM@, windows: false);
while { ~session.isOver.not } { 0.1.wait };
"KF-RESUMED %\n".postf(~session.state);
// The same seeded observer (the simulated participant's seed, 4) through the same staircase, straight.
estimate = FrictionObserver(0.1, 3.5, 0.02, seed: 4).runProcedure(straight);
"KF-STRAIGHT-LEVELS %\n".postf(straight.trials.collect(_.level).join(" "));
"KF-STRAIGHT-CORRECT %\n".postf(straight.trials.collect(_.correct).join(" "));
"KF-STRAIGHT-ESTIMATE %\n".postf(estimate.threshold);
""", MAX=MAX_TRIALS, SESSION=sclang.sc_string(str(session)), SIM=SIM)
    run = sclang.require_ok(sclang.run_with_server(second, jack, timeout=120, name="study-threshold-resume",
                                                   server_options={"numOutputBusChannels": 4}))
    refused = " ".join(" ".join(line) for line in run.lines("KF-REFUSED"))
    assert "not the one the session" in refused and \
        "conditions[0].experiment.procedure.maxTrials: 28 in the session, 5 now" in refused, run.output[-3000:]
    assert run.lines("KF-RESUMED") == [["finished"]], run.output[-3000:]
    straight_levels = [float(v) for v in run.lines("KF-STRAIGHT-LEVELS")[0]]
    straight_correct = run.lines("KF-STRAIGHT-CORRECT")[0]
    straight_estimate = float(run.lines("KF-STRAIGHT-ESTIMATE")[0][0])

    damaged = []
    trials = psychometric.read_trials(trials_csv, damaged)
    assert [d.line for d in damaged] == [k + 1], damaged  # the cut row, the header being line 1
    first_rows = [t for t in trials if t["attempt"] == "1"]
    second_rows = [t for t in trials if t["attempt"] == "2"]
    assert [t["trial"] for t in first_rows] == [str(n) for n in range(1, k)]
    # Numbered on from the cut row's trial: the procedure continued from the k - 1 stored.
    assert [t["trial"] for t in second_rows] == [str(n) for n in range(k, len(straight_levels) + 1)]
    levels = [t["level"] for t in first_rows + second_rows]
    assert np.allclose(levels, straight_levels, rtol=1e-12), (levels, straight_levels)
    assert [str(t["correct"]).lower() for t in first_rows + second_rows] == straight_correct
    events = read_csv(session / "01-forceStep-attempt2" / "events.csv")
    detail = {e["event"]: e["detail"] for e in events}
    assert detail["continue"] == f"1-{k - 1} of attempt 1", detail
    assert json.loads(detail["estimate"])["threshold"] == straight_estimate
    log = read_csv(session / "session.csv")
    assert [r["event"] for r in log] == ["start", "resume", "finish"]
    times = [float(r["timeS"]) for r in log]
    assert times[:1] == session_times[:1] and times == sorted(times), times  # counting on across the resume

    # The report fits exactly the trials the procedure used and says how the attempts joined.
    summary = report.write_report(root, root / "report")
    (fit,) = summary["thresholds"].to_dict("records")
    assert fit["trials"] == len(straight_levels) and fit["estimate"] == straight_estimate
    own = psychometric.fit(straight_levels, [c == "true" for c in straight_correct])
    assert fit["threshold"] == own["threshold"]
    md = (root / "report" / "report.md").read_text()
    joined = f"trials 1-{k - 1} of attempt 1, trials {k}-{len(straight_levels)} of attempt 2"
    assert joined in md, md
    rows = bids.trial_rows(sessions(root)[0])
    assert [r["used"] for r in rows] == ["true"] * len(straight_levels)
    counts = bids.level_counts(rows)[("sub-R1", "forceStep")]
    assert sum(n for _, _, n in counts) == len(straight_levels)
