"""The study report on data made for it, and FrictionStudy.report's refusals: the binds statistic
measures the speed where the friction is raised (not over the whole fragment), and the report
called from sclang says what is missing when its Python packages or python3 are."""
import json

import numpy as np
import pandas as pd
import pytest

from kfharness import paths, sclang
from kfstudy import report_statistics


def made_samples(participants=5):
    """A mapping whose friction is raised on the first half of every 5 mm (0.5 N, else the minimum
    0.14 N), explored back and forth over 20 mm. Friction off, each participant moves at 50 mm/s
    everywhere; on, it is slowed to 20 + k mm/s where the friction is raised and sped to 80 mm/s
    elsewhere: over the whole fragment its median speed is about the same off and on, where the
    friction is it is 30 - k mm/s slower. The report's samples table (report_tables)."""
    x = np.tile(np.linspace(0.01, 19.99, 2000), 3)
    raised = (x % 5) < 2.5
    tables = []
    for k in range(participants):
        for friction in (False, True):
            v = np.where(raised, 20.0 + k, 80.0) if friction else np.full(len(x), 50.0)
            force = np.where(raised, 0.5, 0.14) if friction else np.full(len(x), 0.14)
            tables.append(pd.DataFrame(dict(participant=f"P{k + 1}", position=1 + friction, condition="made",
                                            mapping="made", friction=friction, t_s=np.arange(len(x)) / 125.0,
                                            x_mm=x, v_mm_s=v, force_n=force, inside=True)))
    return pd.concat(tables, ignore_index=True)


def test_binds_measures_the_speed_where_the_friction_is_raised():
    samples = made_samples()
    parts = report_statistics.raised_parts(samples, {"made": (0.0, 20.0)}, 0.14)
    middles = ((parts.from_mm + parts.to_mm) / 2).to_numpy()
    assert list(parts.raised) == list((middles % 5) < 2.5)
    table, pairs = report_statistics.binds(samples, parts)
    assert [(r.participant, r.speed_off, r.speed_on) for r in pairs.itertuples()] == [
        (f"P{k + 1}", 50.0, 20.0 + k) for k in range(5)]
    (row,) = table.to_dict("records")
    assert row["raised_mm"] == 10.0 and row["mean_difference"] == pytest.approx(28.0)
    # The differences 30, 29, ... 26: mean 28, sd 1.58, t = 28 / (1.58 / sqrt 5) = 39.6.
    assert row["t"] == pytest.approx(28 / (np.std([30, 29, 28, 27, 26], ddof=1) / np.sqrt(5)))
    # Over the whole fragment the medians would have shown no binding (the old measure): the
    # participant is as fast as before half the time and faster the other half.
    on = samples[samples.friction]
    assert (on.v_mm_s.abs().groupby(on.participant).median() >= 50).all()


def test_a_mapping_seen_with_friction_off_only_has_no_parts_and_no_pairs():
    samples = made_samples(2)
    off = samples[~samples.friction]
    parts = report_statistics.raised_parts(off, {"made": (0.0, 20.0)}, 0.14)
    table, pairs = report_statistics.binds(off, parts)
    assert len(parts) == 0 and len(pairs) == 0 and len(table) == 0


REPORT = r"""
var root = @ROOT@, out = @OUT@, attempt = { |tag, f|
	try { "KF-REPORTED % %".format(tag, f.value).postln } { |e| "KF-REFUSED % %".format(tag, e.errorString).postln }
};
attempt.(\missing, { FrictionStudy.report(root, out) });
attempt.(\noPython, { FrictionStudy.report(root, out, "/nonexistent/python3") });
attempt.(\noSession, { FrictionStudy.report(out, out) });
"""


def test_the_report_from_sclang_names_what_is_missing():
    work = paths.work_dir() / "study-report-refusals"
    (work / "sessions" / "P1").mkdir(parents=True, exist_ok=True)
    (work / "sessions" / "P1" / "manifest.json").write_text(json.dumps({"participant": "P1"}))
    # A scipy that does not import, found before Debian's: as if python3-scipy were not installed.
    (work / "hide" / "scipy").mkdir(parents=True, exist_ok=True)
    (work / "hide" / "scipy" / "__init__.py").write_text("raise ImportError(\"No module named 'scipy'\")\n")
    out = sclang.run_script(sclang.fill(REPORT, ROOT=sclang.sc_string(str(work / "sessions")),
                                        OUT=sclang.sc_string(str(work / "report"))),
                            routine=True, env={"PYTHONPATH": str(work / "hide")})
    said = {line.split()[1]: line.split(" ", 2)[2] for line in out.splitlines() if line.startswith("KF-")
            and line.split()[0] in ("KF-REPORTED", "KF-REFUSED")}
    missing = said["missing"].split("missing: ")[1].split(". On Debian")[0]
    assert missing.startswith("scipy (") and "numpy" not in missing, said
    assert "sudo apt-get install python3-numpy python3-pandas python3-matplotlib python3-scipy python3-soundfile" in said[
        "missing"]
    assert "/nonexistent/python3 was not found" in said["noPython"], said
    assert "no session in" in said["noSession"], said
