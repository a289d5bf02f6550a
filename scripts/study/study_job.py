"""The study job: FrictionStudy.pilot with its threshold part (FrictionStudy.thresholdConditions)
run by simulated participants (FrictionStudySimParticipant, seeds 1..N) side by side on a realtime
server booted by sclang against JACK's dummy driver, one session per participant under
<out>/sessions/, then the report, made by the extension's FrictionStudy.report, into <out>/.

Usage: scripts/study/study_job.py [--out out/study] [--participants 5] [--explore-s S] [--trials N]
                                  [--interval-s S] [--gap-s S]
"""
import argparse
import shutil
import time
from pathlib import Path

from kfharness import paths, procs, sclang, scratch
from kfharness.jack import performer_jack

# The participants run at once, each on a device slot of its own (deviceIndex) and output pairs of
# its own (participantOut, experimenterOut): a simulated participant needs no one's turn, and its
# audio.wav is its own pair's. The report follows, from sclang as a researcher makes it.
SCRIPT = r"""
var thresholds = if(@TRIALS@ > 0) { FrictionStudy.thresholdConditions(@TRIALS@, \keys, @INTERVAL@, @GAP@) };
var study = FrictionStudy.pilot(600, thresholds), root = @ROOT@, t0 = Main.elapsedTime, sessions, at, progress;
sessions = @PARTICIPANTS@.collect { |i|
	study.run("P" ++ (i + 1), root, s, i, seed: i + 1, simulated: FrictionStudySimParticipant(i + 1, @EXPLORE@),
		windows: false, participantOut: 4 * i, experimenterOut: 4 * i + 2, deviceIndex: i)
};
// A line as each participant comes to a condition, and at its session's end.
at = nil ! sessions.size;
progress = {
	sessions.do { |session, i|
		var now = if(session.isOver) { session.state } { session.position };
		if(now != at[i]) {
			at[i] = now;
			"KF-STUDY-PROGRESS % s  %  %\n".postf((Main.elapsedTime - t0).round(1), session.participant,
				if(session.isOver) { now } { "%/% %".format(now + 1, session.conditionCount, session.order[now].name) })
		}
	}
};
while { progress.value; sessions.any { |session| session.isOver.not } } { 0.1.wait };
"KF-STUDY-SESSIONS % s\n".postf((Main.elapsedTime - t0).round(0.1));
sessions.do { |session| "KF-STUDY-SESSION % %\n".postf(session.participant, session.state) };
sessions.do { |session|
	if(session.state != \finished) { Error("session % ended %".format(session.participant, session.state)).throw }
};
t0 = Main.elapsedTime;
"KF-STUDY-REPORT % % s\n".postf(FrictionStudy.report(root, @OUT@), (Main.elapsedTime - t0).round(0.1));
"""


def run_study(out_dir, participants=5, explore_s=None, trials=40, interval_s=1.5, gap_s=0.5):
    """Runs the sessions into out_dir/sessions (made anew) and the report into out_dir; returns the
    sclang run."""
    out_dir = Path(out_dir)
    sessions = out_dir / "sessions"
    if sessions.exists():
        shutil.rmtree(sessions)
    sessions.mkdir(parents=True)
    code = sclang.fill(SCRIPT, ROOT=sclang.sc_string(str(sessions)), OUT=sclang.sc_string(str(out_dir)),
                       PARTICIPANTS=participants, EXPLORE="nil" if explore_s is None else explore_s, TRIALS=trials,
                       INTERVAL=interval_s, GAP=gap_s)
    # Each condition: at most 600 s of exploring (the pilot's maxTimeS), a few s to open and close;
    # each trial its two intervals and gaps and the procedure's choice; the report a few minutes.
    timeout_s = 6 * ((explore_s or 600) + 15) + 3 * (trials * (2 * (interval_s + gap_s) + 0.5) + 15) + 300
    # As a performer runs it: realtime scheduling where this user may. At normal priority the
    # five participants' server fell to about 500 force frames a second in a fresh clone's run
    # (the audio thread waiting for the CPU), and the binds statistic with it.
    jack = performer_jack()
    try:
        jack.start()
        run = sclang.run_with_server(code, jack, timeout=timeout_s, name="study", progress="KF-STUDY-PROGRESS",
                                     server_options={"numOutputBusChannels": 4 * participants})
    finally:
        jack.stop()
    return run


def main():
    procs.finish_on_sigterm()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(paths.REPO_DIR / "out" / "study"))
    parser.add_argument("--participants", type=int, default=5)
    parser.add_argument("--explore-s", type=float, default=None)
    parser.add_argument("--trials", type=int, default=40, help="trials of each threshold experiment (0: none)")
    parser.add_argument("--interval-s", type=float, default=1.5)
    parser.add_argument("--gap-s", type=float, default=0.5)
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    run = run_study(out, args.participants, args.explore_s, args.trials, args.interval_s, args.gap_s)
    for tag in ("KF-STUDY-SESSIONS ", "KF-STUDY-SESSION ", "KF-STUDY-REPORT "):
        for fields in run.lines(tag):
            print(tag.removeprefix("KF-STUDY-").strip().lower(), " ".join(fields), flush=True)
    sclang.require_ok(run, "the study")
    print((out / "report.log").read_text(), end="")
    print(f"the study job took {time.monotonic() - t0:.0f} s")


if __name__ == "__main__":
    with scratch.for_job():  # its scratch folder removed when it passed
        main()
