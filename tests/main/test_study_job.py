"""scripts/study.sh, the README's study command, shortened: each simulated exploration cut to 3 s
and each threshold experiment to 24 trials of 0.2 s intervals. It sets up, builds, runs the pilot
study and its threshold part with five simulated participants side by side on a realtime server,
and writes the sessions and the report (FrictionStudy.report, from sclang) into KF_STUDY_JOB_OUT.
The test checks the sessions, the report's figures (PNG) and tables (CSV) against the sessions,
the binds statistic (where it measures, and its test), the puck held where friction is raised,
and the threshold fits against the model observers' known thresholds."""
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

from kfharness import bids_check, paths, profile
from kfstudy import bids, psychometric, readers, report_statistics, report_tables, session_folder

OUT = Path(os.environ["KF_STUDY_JOB_OUT"])
PILOT = ["mapping1-off", "mapping1-on", "mapping2-off", "mapping2-on", "mapping3-off", "mapping3-on"]
THRESHOLDS = {"forceStep": "force", "asynchrony": "asynchrony", "gratingStep": "grating"}
CONDITIONS = PILOT + list(THRESHOLDS)
EXPLORE_S, TRIALS, INTERVAL_S, GAP_S = 3, 24, 0.2, 0.05


def png_size(path):
    from PIL import Image
    with Image.open(path) as image:
        pixels = np.asarray(image.convert("L"))
    assert pixels.std() > 10, f"{path.name} is blank"
    return pixels.shape


def test_the_study_job_writes_five_sessions_and_their_report():
    shutil.rmtree(OUT, ignore_errors=True)
    run = subprocess.run(["bash", str(paths.REPO_DIR / "scripts" / "study.sh"), "--out", str(OUT),
                          "--explore-s", str(EXPLORE_S), "--trials", str(TRIALS), "--interval-s", str(INTERVAL_S),
                          "--gap-s", str(GAP_S)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         timeout=840)
    # The job's progress (a line as each participant comes to a condition): where each one was.
    where = {}
    for line in run.stdout.splitlines():
        if re.fullmatch(r"[\d.]+ s  (P\d)  .*", line):
            where[line.split()[2]] = line
    assert run.returncode == 0, "\n".join(where.values()) + "\n...\n" + run.stdout[-3000:]
    assert sorted(where) == ["P1", "P2", "P3", "P4", "P5"] and all(w.endswith("finished") for w in where.values()), where

    # Five sessions, each the pilot's six conditions in the paper's order and the three threshold
    # experiments, each run to its end once.
    sessions = session_folder.sessions(OUT / "sessions")
    assert [s.participant for s in sessions] == ["P1", "P2", "P3", "P4", "P5"]
    for s in sessions:
        assert s.finished and s.manifest["order"] == CONDITIONS
        assert [c.complete and c.attempts == 0 for c in s.conditions] == [True] * 9
        for c in s.conditions[:6]:
            # Ended by the participant: when covered enough, or after its 3 s of exploring (checked
            # every 0.05 s; 1 s for sclang's clock to wake up late on a busy machine).
            assert c.ended_by == "participant" and 0.5 < c.duration_s < EXPLORE_S + 1.0, (s.participant, c.name)
            assert (c.folder / "audio.wav").stat().st_size > 0 and (c.folder / "device.kfsession").stat().st_size > 0
            check_rests_until_start(c)
        for c in s.conditions[6:]:
            # Ended by the procedure after its trials, each a line of trials.csv; the participant's
            # model observer logged with its known threshold, the one its manifest holds.
            assert c.ended_by == "procedure" and c.is_threshold, (s.participant, c.name)
            observer = c.event_json("observer")
            assert observer["threshold"] == s.manifest["simulatedParticipant"]["thresholds"][THRESHOLDS[c.name]]
            assert c.event_json("experiment")["kind"] == THRESHOLDS[c.name]
        trials = session_folder.read_csv(s.folder / "trials.csv")
        assert [t["condition"] for t in trials] == [name for name in THRESHOLDS for _ in range(TRIALS)]
        assert {(a["condition"], a["question"]) for a in s.answers} == {
            (c, q) for c in PILOT for q in (["audio"] if c.endswith("off") else ["touch", "relation"])} | {
            (c, "how") for c in THRESHOLDS}

    # The report: a row per condition run, its figures there and drawn.
    report = (OUT / "report.md").read_text()
    table = session_folder.read_csv(OUT / "conditions.csv")
    assert len(table) == 45
    for r in table:
        assert f"![{r['condition']}]({r['figure3']})" in report
        assert png_size(OUT / r["figure3"]) == (540, 810)  # 9 x 6 in at 90 dpi
    for name in ["speeds.png", "binds.png"] + [f"{kind}-P{i}.png" for i in range(1, 6) for kind in ("coverage", "speeds")]:
        assert f"({name})" in report
        png_size(OUT / name)
    check_coverage_maps(sessions, table)
    check_binds()
    check_threshold_fits(sessions, report)
    check_bids(sessions)


def check_coverage_maps(sessions, table):
    """The map the experimenter saw (logged as coverageMap) against the one the report computes
    from the recording, cell by cell, and the report's count of the cells apart."""
    rows = {(r["participant"], r["condition"]): r for r in table if r["threshold"] == "False"}
    for s in sessions:
        for c in s.conditions[:6]:
            live = c.live_cells()
            t, x, v = c.track()
            recording = session_folder.coverage(x, v, c.area_mm, s.coverage_settings)
            where = (s.participant, c.name, np.argwhere(live & ~recording).tolist(), np.argwhere(recording & ~live).tolist())
            row = rows[(s.participant, c.name)]
            # The session makes its map from the recording as the server writes it
            # (FrictionStudyTrack), the same samples as the report's track: the two are the same
            # map, whatever the machine did to the device thread. Before, the live map was of the
            # trajectory rendered as the reports came, and a fresh clone whose kernel held the
            # device thread back 30 to 37 ms at a time saw it 10 cells from the recording's.
            assert (live == recording).all(), where
            assert int(row["coverage_cells_apart"]) == 0, where
            assert float(row["coverage_live"]) == round(live.mean(), 3) == round(float(row["coverage_recording"]), 3), where
            # Explored, not empty: the simulated participants sweep the fragment at several speeds.
            assert recording.any(axis=0).sum() >= 3 and recording.any(axis=1).sum() >= 5, where


def check_bids(sessions):
    """The study as BIDS behavioural data, read with pandas: each column against its sidecar, a
    trials and an answers table per participant, every trial once in the tidy table, and the counts
    per level psignifit reads adding up to the trials."""
    tables = bids_check.read_checked(OUT / "bids")
    assert list(tables["participants.tsv"]["participant_id"]) == [f"sub-{s.participant}" for s in sessions]
    tidy = tables["derivatives/kfstudy/trials.tsv"]
    assert len(tidy) == len(sessions) * len(THRESHOLDS) * TRIALS
    assert dict(zip(tidy["condition"], tidy["unit"])) == {"forceStep": "N", "asynchrony": "ms", "gratingStep": "mm"}
    for s in sessions:
        task = bids.label(s.manifest["study"]["name"])  # letters and digits of the study's name
        stem = f"sub-{s.participant}/beh/sub-{s.participant}_task-{task}"
        assert len(tables[f"{stem}_acq-trials_beh.tsv"]) == len(THRESHOLDS) * TRIALS
        assert len(tables[f"{stem}_acq-answers_beh.tsv"]) == len(s.answers)
        for condition in THRESHOLDS:
            counts = tables[f"derivatives/kfstudy/sub-{s.participant}_cond-{condition}_counts.tsv"].astype(float)
            mine = tidy[(tidy["participant_id"] == f"sub-{s.participant}") & (tidy["condition"] == condition)]
            assert counts["n_total"].sum() == len(mine) == TRIALS
            assert counts["n_correct"].sum() == (mine["correct"] == "true").sum()


def frame_rates():
    """Per friction-on condition, the force frames the devices applied per second (1000 when the
    server's audio keeps pace) and their watchdog trips, over all sessions: for the failure
    message of a check that needs the force rendered (fresh clones' runs have had 430 to 900 a
    second and 4 to 35 trips per condition, with the mapping 2 parts far from the ends low, while
    Wine made its prefix beside them: ARCHITECTURE.md, "Tests and checks")."""
    rates = {}
    for f in sorted((OUT / "sessions").glob("*/*-on/device.kfsession")):
        s = readers.Session(f)
        span = s.frames[-1, 0] - s.frames[0, 0] if len(s.frames) > 1 else 0.0
        rates.setdefault(f.parent.name, []).append(
            (round(len(s.frames) / span) if span else 0, s.off_causes.count("watchdog")))
    return rates


# How long after the position it was computed from a force acts (the report's interpolation, the
# block, the frame: 10 to 15 ms, check_binds).
FORCE_LAG_S = 0.015


def check_binds():
    """Where the statistic measures, and its test. The paper's participants were slowed where the
    friction is: the report measures the speed in the parts of the fragment where the force
    commanded with friction on is raised (how it picks them and what it makes of the speeds there
    is tested on data made for it: tests/scenes/test_study_report.py). Here, that the parts it
    picked in the runs are where the pilot's signal puts the friction. In mappings 1 and 2 the
    signal is a sine of amplitude 1 whose cycles (0.025 and 0.2 mm) are far shorter than a part
    (0.5 mm): every part crossed is loud, and raised. In mapping 3 a cycle is 12.5 mm and the force
    follows |sine| (1 ms of it is under 0.4 mm at the speeds explored), low at its zero crossings
    every 6.25 mm; it is felt where the puck is when it acts, 10 to 15 ms after the position it was
    computed from (the report's interpolation, the block, the frame), so the low parts lie up to
    0.5 mm past a crossing when crossed at 40 mm/s and further when faster. A part 1.5 mm or more
    from a crossing (|sine| >= 0.71, -3 dB: 0.45 N when crossed slowly) and more than 2 mm from the
    fragment's ends (where the hands turn, slowly, and the sound and its force fall: as in mappings
    1 and 2) is raised but for a few crossed fast: measured in four fresh clones' runs of this job,
    0, 0, 1 and 1 of 47 to 53 such parts were not, each 1.5 mm from a crossing, and 1 of 2 at the
    ends was not (96.75 mm of 97); in CI, 5 of 50 counted with the ends were not. Some parts, at the
    crossings, are not raised."""
    parts = session_folder.read_csv(OUT / "binds-parts.csv")
    judged = {m: [p for p in parts if p["mapping"] == m and p["mean_force_n"] not in ("", "nan")]
              for m in ("mapping1", "mapping2", "mapping3")}
    samples = report_tables.load(OUT / "sessions").samples
    for mapping in ("mapping1", "mapping2"):
        # Near a fragment's ends the parts may be lower: the hands turn beyond the ends (3 to 4 mm
        # out, measured) and come back fast, and the force a report shows was computed from where
        # the puck was up to FORCE_LAG_S before, outside the fragment, where nothing sounds (a part
        # 2 to 2.5 mm from the end was low, its reports up to 274 mm/s). So a low part lies within
        # the distance its fastest report of friction on covers in FORCE_LAG_S (a part further in
        # would need a speed far above any measured), plus a part; every other part is raised.
        ends = (float(judged[mapping][0]["from_mm"]), float(judged[mapping][-1]["to_mm"]))
        on = samples[(samples.mapping == mapping) & samples.friction.astype(bool)]
        x_mm, speed = on.x_mm.to_numpy(float), np.abs(on.v_mm_s.to_numpy(float))
        assert len(judged[mapping]) >= 10, (mapping, judged[mapping])
        for p in judged[mapping]:
            if p["raised"] == "True":
                continue
            a, b = float(p["from_mm"]), float(p["to_mm"])
            fastest = np.nanmax(speed[(x_mm >= a) & (x_mm < b)], initial=0.0)
            reach_mm = FORCE_LAG_S * fastest + report_statistics.BIND_BIN_MM
            assert a < ends[0] + reach_mm or b > ends[1] - reach_mm, (mapping, ends, (a, b), reach_mm, frame_rates())
    lo = np.array([float(p["from_mm"]) for p in judged["mapping3"]])
    hi = np.array([float(p["to_mm"]) for p in judged["mapping3"]])
    middles = (lo + hi) / 2
    raised = np.array([p["raised"] == "True" for p in judged["mapping3"]])
    from_crossing_mm = np.abs((middles + 3.125) % 6.25 - 3.125)
    inner = (lo >= lo[0] + 2) & (hi <= hi[-1] - 2)
    crest = (from_crossing_mm >= 1.5) & inner
    low_crests = [float(m) for m in middles[crest & ~raised]]
    assert crest.sum() >= 10 and raised[crest].mean() > 0.9, (low_crests, frame_rates())
    assert 0 < raised.sum() < len(raised), raised

    # The test is the paired t test of the per-participant differences, per mapping.
    pairs = session_folder.read_csv(OUT / "binds.csv")
    tests = {r["mapping"]: r for r in session_folder.read_csv(OUT / "binds-test.csv")}
    assert len(pairs) == 15 and sorted(tests) == ["mapping1", "mapping2", "mapping3"]
    for mapping, test in tests.items():
        d = np.array([float(p["speed_off"]) - float(p["speed_on"]) for p in pairs if p["mapping"] == mapping])
        t = d.mean() / (d.std(ddof=1) / np.sqrt(len(d)))
        assert int(test["n"]) == 5 and abs(float(test["t"]) - t) < 1e-9 * abs(t), (mapping, test, t)
    # No sign is asserted of the typical speeds' difference: in these 3 s explorations it is not
    # the friction's to decide. A participant's intended speed steps up every 0.5 s whether or not
    # the puck moves, so one held at the fragment crosses it later, in a faster step: mapping 1's
    # difference was negative for P5 in all of six runs (fresh clones 19 to 23 and one more at
    # e64f5f0: -2.1 to -5.2 mm/s), for P4 in two (down to -10.5), and its mean over the five once
    # (-1.15). That the friction binds the puck is checked where it does: check_held.
    check_held()


def check_rests_until_start(c):
    """The simulated participant's hand starts with the condition: no report before the start
    line moved the puck (its device opens held, FrictionDevice.releaseHand at the start). Once the
    set-up before a condition's friction took 0.06 to 1.5 s, the more the busier the machine, and
    the hand explored without the friction. A report is placed by its device time from the first
    (session_folder.track), which came at most one report period after recordDevice was logged,
    and the release is sent after the start line: one moving before start minus that period is
    the hand's early."""
    r = c.recording.reports
    t = r[:, 1] - r[0, 1] + c.event_time("recordDevice")
    early = t < c.start_s - 1.0 / profile.device()["updateRateHz"]
    assert early.sum() >= 2 and not r[early, 2].any(), (c.folder, t[early][r[early, 2] != 0][:5])


def check_held():
    """Where mappings 1 and 2 raise the friction (0.5 N against the 0.14 N of friction off), the
    puck stands still longer with friction on, for every participant: its push rises by maxPushN
    per adaptS (0.43 to 0.94 N/s for these five) until the puck slides, so passing 0.5 N rather
    than 0.14 N holds it about 0.4 to 0.8 s more. Measured over six runs (the ones named above),
    the time standing still in the raised parts rose by 0.29 to 0.73 s (the least: mapping 2, P4,
    0.05 to 0.34 s); at least 0.15 s, half the least, is asserted. Mapping 3 raises its friction
    in bumps, and the puck also stands still between them, so none there."""
    import pandas as pd
    from kfstudy import report_statistics, report_tables
    samples = report_tables.load(OUT / "sessions").samples
    parts = pd.read_csv(OUT / "binds-parts.csv")
    parts["part"] = parts.groupby("mapping").cumcount()
    parts["raised"] = parts.raised.fillna(False).astype(bool)
    still = samples[report_statistics.where_raised(samples, parts) & (samples.v_mm_s.astype(float) == 0)]
    # A sample per mouse report.
    held_s = (still.groupby([still.mapping, still.participant, still.friction.astype(bool)]).size()
              / profile.device()["updateRateHz"])
    for mapping in ("mapping1", "mapping2"):
        for participant in ("P1", "P2", "P3", "P4", "P5"):
            off, on = (held_s.get((mapping, participant, friction), 0.0) for friction in (False, True))
            assert on >= off + 0.15, (mapping, participant, off, on, frame_rates())


def check_threshold_fits(sessions, report):
    """Each threshold fit against the known threshold of the model observer that answered it.
    The answers are the observer's (its own seeded random numbers) and QUEST+ chooses each level
    from them, so a run gives the same 15 fits every time: the bound is what theory says such a fit
    can do. The theory's smallest sd of an unbiased log10 threshold from a run's levels is the
    Cramer-Rao bound (psychometric.cramer_rao_sd_log10: the Fisher information of the answers at
    the observer's threshold, slope 3.5 and lapse 0.02), 0.09 to 0.19 log10 for these runs of 24
    trials. The fit holds its lapse rate within [0, 0.05] and its slope within [0.2, 20], so it
    varies less than the bound, with a small bias (the bench: 48 QUEST+ trials, fit sd 0.055
    against a bound of 0.072, bias +0.017). So each fit lies within 3 bounds of its observer's
    threshold (a normal estimate with the bound's sd stays within 3 sd 99.7 % of the time; these
    fits were within 1.05), and the mean over the five participants of an experiment within 3
    bounds / sqrt(5) (the mean's sd); the procedure's own estimate (QUEST+'s posterior mean) the
    same."""
    fits = session_folder.read_csv(OUT / "thresholds.csv")
    assert len(fits) == 15
    by_experiment = {}
    for fit in fits:
        session = next(s for s in sessions if s.participant == fit["participant"])
        trials = [t for t in session_folder.read_csv(session.folder / "trials.csv") if t["condition"] == fit["condition"]]
        known = session.manifest["simulatedParticipant"]["thresholds"][THRESHOLDS[fit["condition"]]]
        assert int(fit["trials"]) == TRIALS and float(fit["observer_threshold"]) == known
        bound = psychometric.cramer_rao_sd_log10([float(t["level"]) for t in trials], known, 3.5, 0.5, 0.02)
        errors = [np.log10(float(fit[key]) / known) for key in ("threshold", "estimate")]
        assert all(abs(e) < 3 * bound for e in errors), (fit, bound)
        by_experiment.setdefault(fit["condition"], []).append((errors, bound))
        assert f"({fit['participant']}-{fit['condition']}-psychometric.png)" in report
        png_size(OUT / f"{fit['participant']}-{fit['condition']}-psychometric.png")
    for condition, entries in by_experiment.items():
        bound = np.sqrt(np.mean([b ** 2 for _, b in entries]) / len(entries))
        for k in (0, 1):
            mean = np.mean([e[k] for e, _ in entries])
            assert abs(mean) < 3 * bound, (condition, k, mean, bound)
    assert sorted((f["participant"], f["condition"]) for f in fits) == sorted(
        (s.participant, name) for s in sessions for name in THRESHOLDS)
