"""A study's data as researchers exchange it: BIDS behavioural data (BIDS 1.9, "Behavioral
experiments (with no neural recordings)") beside the report, and one tidy trials table.

    bids/dataset_description.json, participants.tsv + .json
    bids/sub-<code>/beh/sub-<code>_task-<study>_acq-trials_beh.tsv + .json   (threshold trials)
    bids/sub-<code>/beh/sub-<code>_task-<study>_acq-answers_beh.tsv + .json  (questions' answers)
    bids/derivatives/kfstudy/trials.tsv + .json      (every trial of the study, one row each)
    bids/derivatives/kfstudy/sub-<code>_cond-<condition>_counts.tsv  (level, n_correct, n_total:
                                                      the matrix psignifit reads)

Each .json sidecar describes every column of its table (Description, and Units or Levels).
Labels keep only letters and digits, as BIDS asks. Values missing are "n/a"."""
import csv
import json
import re

from . import checked_csv
from .psychometric import procedure_trials

BIDS_VERSION = "1.9.0"
LEVEL_UNITS = {"force": "N", "asynchrony": "ms", "grating": "mm"}

TRIAL_COLUMNS = {
    "participant_id": dict(Description="The participant, as sub-<label>."),
    "condition": dict(Description="The threshold condition's name in the study."),
    "position": dict(Description="The condition's place in the participant's order, from 1."),
    "attempt": dict(Description="The condition's attempt (a crash or a repeat runs it again)."),
    "trial": dict(Description="The trial's number in the condition's procedure, from 1 (a resumed attempt "
                              "numbers on)."),
    "level": dict(Description="The stimulus level the procedure chose (the difference the participant "
                              "was to detect); its unit is in the column unit."),
    "unit": dict(Description="The unit of level.", Levels=dict(N="newtons (a force step)",
                                                               ms="milliseconds (an audio-touch asynchrony)",
                                                               mm="millimetres (a grating's period step)")),
    "target": dict(Description="The interval that held the stimulus.", Levels={"1": "first", "2": "second"}),
    "response": dict(Description="The interval the participant chose.", Levels={"1": "first", "2": "second"}),
    "correct": dict(Description="Whether the response was the target interval.",
                    Levels={"true": "correct", "false": "wrong"}),
    "onset": dict(Description="The trial's start, from the condition's prepare line.", Units="s"),
    "interval1_onset": dict(Description="The first interval's start, from the condition's prepare line.", Units="s"),
    "interval2_onset": dict(Description="The second interval's start, from the condition's prepare line.", Units="s"),
    "response_time": dict(Description="When the response was given, from the condition's prepare line.", Units="s"),
    "wall_time": dict(Description="Local date and time the trial was stored (ISO 8601)."),
    "used": dict(Description="Whether the condition's procedure used the trial (a resumed attempt continues the "
                             "procedure from the trials stored before it; a trial a later attempt ran again is "
                             "not used).", Levels={"true": "used", "false": "run again by a later attempt"}),
    "experiment": dict(Description="What the threshold is of.", Levels=dict(
        force="a force step on a base force", asynchrony="the delay between the audio and the touch",
        grating="a grating's period")),
    "procedure": dict(Description="The adaptive or fixed procedure that chose the levels.", Levels=dict(
        staircase="a transformed up-down staircase", questPlus="QUEST+ (Watson 2017)",
        constantStimuli="the method of constant stimuli")),
    "base_force": dict(Description="The force both intervals share (force experiments).", Units="N"),
    "interval_duration": dict(Description="Each interval's length.", Units="s"),
    "gap_duration": dict(Description="The pause between the two intervals.", Units="s"),
    "experiment_seed": dict(Description="The seed of the experiment's random choices."),
    "session_seed": dict(Description="The seed of the participant's session (its order)."),
}

ANSWER_COLUMNS = {
    "participant_id": TRIAL_COLUMNS["participant_id"],
    "condition": dict(Description="The condition the question followed."),
    "position": TRIAL_COLUMNS["position"],
    "attempt": TRIAL_COLUMNS["attempt"],
    "question": dict(Description="The question's key in the study."),
    "kind": dict(Description="The question's kind.", Levels=dict(text="free text", rating="a rating on a scale",
                                                                  choice="one of given choices")),
    "answer": dict(Description="The answer as given."),
    "source": dict(Description="Who answered.", Levels=dict(participant="the participant",
                                                              simulated="a simulated participant")),
    "onset": dict(Description="When the answer was given, in the session's time.", Units="s"),
    "wall_time": TRIAL_COLUMNS["wall_time"],
}

PARTICIPANT_COLUMNS = {
    "participant_id": TRIAL_COLUMNS["participant_id"],
    "code": dict(Description="The participant code the session was run with."),
    "session_seed": TRIAL_COLUMNS["session_seed"],
    "order": dict(Description="The conditions in the order run, separated by spaces."),
    "device": dict(Description="The friction device's kind.", Levels=dict(
        sim="the simulated device", replay="a recorded session replayed",
        mouse="a mouse (with the friction board or audio drive, if any)")),
    "finished": dict(Description="Whether the session ran to its end.", Levels={"true": "yes", "false": "no"}),
}

COUNT_COLUMNS = {
    "level": dict(Description="A stimulus level (the unit is the trials table's)."),
    "n_correct": dict(Description="Correct responses at that level."),
    "n_total": dict(Description="Trials at that level."),
}


def label(text):
    """A BIDS label: letters and digits only."""
    return re.sub(r"[^A-Za-z0-9]", "", str(text)) or "x"


def _write_tsv(path, columns, rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        writer = csv.writer(f, delimiter="\t", lineterminator="\n")
        writer.writerow(list(columns))
        for row in rows:
            writer.writerow(["n/a" if row.get(c) in (None, "") else _tsv_value(row[c]) for c in columns])


def _tsv_value(value):
    text = str(value).lower() if isinstance(value, bool) else str(value)
    return text.replace("\t", " ").replace("\r", " ").replace("\n", " ")


def _write_json(path, data):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=2) + "\n")  # in the tables' column order


def _experiments(session):
    """Per threshold condition's folder name: its experiment (the JSON of its events)."""
    return {c.name: (c.event_json("experiment") or {}) for c in session.conditions if c.is_threshold}


def trial_rows(session, damaged=None):
    """The session's trials as tidy rows (TRIAL_COLUMNS); damaged rows skipped (checked_csv)."""
    path = session.folder / "trials.csv"
    if not path.exists():
        return []
    experiments = _experiments(session)
    stored = checked_csv.read_rows(path, damaged)
    used = {id(t) for name in {t["condition"] for t in stored}
            for t in procedure_trials([t for t in stored if t["condition"] == name])[0]}
    rows = []
    for t in stored:
        experiment = experiments.get(t["condition"], {})
        procedure = experiment.get("procedure") or {}
        rows.append(dict(
            participant_id=f"sub-{label(session.participant)}", condition=t["condition"],
            position=t["position"], attempt=t["attempt"], trial=t["trial"], level=t["level"],
            unit=LEVEL_UNITS.get(experiment.get("kind"), ""), target=t["target"], response=t["answer"],
            correct=t["correct"], onset=t["startS"], interval1_onset=t["interval1S"],
            interval2_onset=t["interval2S"], response_time=t["answerS"], wall_time=t["wallTime"],
            experiment=experiment.get("kind"), procedure=procedure.get("kind"),
            base_force=(experiment.get("settings") or {}).get("baseForceN"),
            interval_duration=experiment.get("intervalS"), gap_duration=experiment.get("gapS"),
            experiment_seed=experiment.get("seed"), session_seed=session.manifest.get("seed"),
            used="true" if id(t) in used else "false"))
    return rows


def answer_rows(session):
    return [dict(participant_id=f"sub-{label(session.participant)}", condition=a["condition"],
                 position=a["position"], attempt=a["attempt"], question=a["question"], kind=a["kind"],
                 answer=a["answer"], source=a["source"], onset=a["timeS"], wall_time=a["wallTime"])
            for a in session.answers]


def level_counts(rows):
    """{(participant_id, condition): [(level, n_correct, n_total)]} of the trials the procedures
    used, levels ascending."""
    counts = {}
    for r in (r for r in rows if r["used"] == "true"):
        key = (r["participant_id"], r["condition"])
        cell = counts.setdefault(key, {}).setdefault(float(r["level"]), [0, 0])
        cell[0] += str(r["correct"]).lower() == "true"
        cell[1] += 1
    return {key: [(level, *cell) for level, cell in sorted(levels.items())] for key, levels in counts.items()}


def sidecar(columns):
    return {name: dict(description) for name, description in columns.items()}


def write(sessions, out_dir):
    """Writes the BIDS folder of `sessions` (session_folder.StudySession) into out_dir; returns
    the tidy trials rows of the whole study."""
    study = sessions[0].manifest["study"]["name"] if sessions else "study"
    task = label(study)
    version = sessions[0].manifest.get("version", "unknown") if sessions else "unknown"
    made_by = dict(Name="KineticFriction", Version=str(version))
    provenance = sessions[0].manifest.get("provenance") if sessions else None
    if provenance:  # the first session's; each manifest.json keeps its own
        made_by["Description"] = (f"commit {provenance.get('commit')} (uncommitted changes: "
                                  f"{provenance.get('uncommittedChanges')}), SuperCollider {provenance.get('supercollider')} "
                                  f"on {provenance.get('platform')}, time zone {provenance.get('timeZone')}")
    _write_json(out_dir / "dataset_description.json", dict(
        Name=study, BIDSVersion=BIDS_VERSION, DatasetType="raw", GeneratedBy=[made_by]))
    participants = [dict(participant_id=f"sub-{label(s.participant)}", code=s.participant,
                         session_seed=s.manifest.get("seed"), order=" ".join(s.manifest.get("order", [])),
                         device=(s.manifest.get("device") or {}).get("kind"), finished=s.finished)
                    for s in sessions]
    _write_tsv(out_dir / "participants.tsv", PARTICIPANT_COLUMNS, participants)
    _write_json(out_dir / "participants.json", sidecar(PARTICIPANT_COLUMNS))
    study_trials = []
    for s in sessions:
        beh = out_dir / f"sub-{label(s.participant)}" / "beh"
        stem = f"sub-{label(s.participant)}_task-{task}"
        trials = trial_rows(s)  # its damaged rows are the report's to list
        if trials:
            _write_tsv(beh / f"{stem}_acq-trials_beh.tsv", TRIAL_COLUMNS, trials)
            _write_json(beh / f"{stem}_acq-trials_beh.json", dict(TaskName=study, **sidecar(TRIAL_COLUMNS)))
        answers = answer_rows(s)
        if answers:
            _write_tsv(beh / f"{stem}_acq-answers_beh.tsv", ANSWER_COLUMNS, answers)
            _write_json(beh / f"{stem}_acq-answers_beh.json", dict(TaskName=study, **sidecar(ANSWER_COLUMNS)))
        study_trials += trials
    derivatives = out_dir / "derivatives" / "kfstudy"
    _write_json(derivatives / "dataset_description.json", dict(
        Name=f"{study}: tidy trials and counts per level", BIDSVersion=BIDS_VERSION, DatasetType="derivative",
        GeneratedBy=[dict(Name="KineticFriction kfstudy", Version=str(version))]))
    _write_tsv(derivatives / "trials.tsv", TRIAL_COLUMNS, study_trials)
    _write_json(derivatives / "trials.json", sidecar(TRIAL_COLUMNS))
    for (participant_id, condition), counts in level_counts(study_trials).items():
        _write_tsv(derivatives / f"{participant_id}_cond-{label(condition)}_counts.tsv", COUNT_COLUMNS,
                   [dict(level=a, n_correct=b, n_total=c) for a, b, c in counts])
    _write_json(derivatives / "counts.json", sidecar(COUNT_COLUMNS))
    return study_trials
