"""The study job: FrictionStudy.pilot with simulated participants (FrictionStudySimParticipant,
seeds 1..N) on a realtime server booted by sclang against JACK's dummy driver, one session per
participant under <out>/sessions/, then the report (kfharness.study_report) into <out>/.

Usage: scripts/study/study_job.py [--out out/study] [--participants 5] [--explore-s S]
"""
import argparse
import shutil
import time
from pathlib import Path

from kfharness import paths, sclang, study_report
from kfharness.jack import JackServer

SCRIPT = r"""
var study = FrictionStudy.pilot, root = @ROOT@;
@PARTICIPANTS@.do { |i|
	var code = "P" ++ (i + 1), session, t0 = Main.elapsedTime;
	session = study.run(code, root, s, i, seed: i + 1,
		simulated: FrictionStudySimParticipant(i + 1, @EXPLORE@), windows: false);
	while { session.isOver.not } { 0.1.wait };
	"KF-STUDY-SESSION % % % s".format(code, session.state, (Main.elapsedTime - t0).round(0.1)).postln;
	if(session.state != \finished) { Error("session % ended %".format(code, session.state)).throw };
};
"""


def run_study(out_dir, participants=5, explore_s=None, timeout_s=None):
    """Runs the sessions into out_dir/sessions (made anew) and returns the sclang run."""
    sessions = Path(out_dir) / "sessions"
    if sessions.exists():
        shutil.rmtree(sessions)
    sessions.mkdir(parents=True)
    code = sclang.fill(SCRIPT, ROOT=sclang.sc_string(str(sessions)), PARTICIPANTS=participants,
                       EXPLORE="nil" if explore_s is None else explore_s)
    # Each condition: at most 600 s of exploring (the pilot's maxTimeS), a few s to open and close.
    timeout_s = timeout_s or participants * 6 * ((explore_s or 600) + 15) + 60
    jack = JackServer()
    jack.start()
    try:
        run = sclang.run_with_server(code, jack, timeout=timeout_s, name="study",
                                     server_options={"numOutputBusChannels": 4})
    finally:
        jack.stop()
    return run


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(paths.REPO_DIR / "out" / "study"))
    parser.add_argument("--participants", type=int, default=5)
    parser.add_argument("--explore-s", type=float, default=None)
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    run = run_study(out, args.participants, args.explore_s)
    for fields in run.lines("KF-STUDY-SESSION"):
        print("session", " ".join(fields), flush=True)
    sclang.require_ok(run, "the study")
    summary = study_report.write_report(out / "sessions", out)
    print(f"{len(summary['sessions'])} sessions, report {out / 'report.md'} ({time.monotonic() - t0:.0f} s)")
    for r in summary["binds"]:
        print(f"binds, {r['group']}: off {r['mean_off']:.1f} mm/s, on {r['mean_on']:.1f} mm/s, "
              f"t({r['df']}) = {r['t']:.2f}, p = {r['p']:.3g}")


if __name__ == "__main__":
    main()
