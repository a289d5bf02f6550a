"""The session folder's event names, one vocabulary for both sides: FrictionStudySession's
conditionEvents and sessionEvents (its log refuses any other name) are kfstudy.session_folder's
CONDITION_EVENTS and SESSION_EVENTS, and every name the Python side looks up is one of them."""
import re

import numpy as np

from kfharness import paths, sclang_session
from kfstudy import session_folder


def test_sclang_and_python_name_the_same_events():
    out = sclang_session.run(r"""
"KF-CONDITION %".format(FrictionStudySession.conditionEvents.join(" ")).postln;
"KF-SESSION %".format(FrictionStudySession.sessionEvents.join(" ")).postln;
try { FrictionStudySession.checkEvent(\strat) } { |e| "KF-REFUSED %".format(e.what).postln };
try { FrictionStudySession.checkEvent(\prepare, true) } { |e| "KF-REFUSED-SESSION %".format(e.what).postln };
"KF-ACCEPTED % %".format(FrictionStudySession.checkEvent(\prepare), FrictionStudySession.checkEvent(\finish, true)).postln;
""")
    lines = {line.split()[0]: line.split()[1:] for line in out.splitlines() if line.startswith("KF-")}
    assert tuple(lines["KF-CONDITION"]) == session_folder.CONDITION_EVENTS
    assert tuple(lines["KF-SESSION"]) == session_folder.SESSION_EVENTS
    assert "'strat' is not a condition event" in " ".join(lines["KF-REFUSED"]), out[-2000:]
    assert "'prepare' is not a session event" in " ".join(lines["KF-REFUSED-SESSION"])
    assert lines["KF-ACCEPTED"] == ["prepare", "finish"]


def test_every_event_named_in_the_code_is_in_the_vocabulary():
    # sclang: this.log(\name ...) and prSessionLog(\name ...); Python: the names it looks up.
    sc = "".join(p.read_text() for p in (paths.REPO_DIR / "sc-classes").rglob("*.sc"))
    logged = set(re.findall(r"this\.log\(\\(\w+)", sc))
    session = set(re.findall(r"prSessionLog\(\\(\w+)", sc))
    py = "".join(p.read_text() for p in (paths.REPO_DIR / "python" / "kfstudy").glob("*.py"))
    looked_up = set(re.findall(r"event_(?:time|detail|json)\(\"(\w+)\"", py))
    assert logged and session and looked_up
    assert logged <= set(session_folder.CONDITION_EVENTS), logged - set(session_folder.CONDITION_EVENTS)
    assert session <= set(session_folder.SESSION_EVENTS), session - set(session_folder.SESSION_EVENTS)
    assert looked_up <= set(session_folder.CONDITION_EVENTS), looked_up - set(session_folder.CONDITION_EVENTS)


def test_the_coverage_map_logged_reads_back_as_the_cells_covered():
    # FrictionStudyCoverage.mapString, the coverageMap event's detail, read by Condition.live_cells.
    out = sclang_session.run(r"""
var c = FrictionStudyCoverage([0, 6], 5, 300, 10, 6, 0.5);
c.add(0, 2.9, 20); c.add(4.5, 6, 250); c.add(7, 9, 20);
"KF-MAP %".format(c.mapString).postln;
c.cells.do { |row, p| row.do { |covered, v| if(covered) { "KF-CELL % %".format(p, v).postln } } };
""")
    detail = next(line.split()[1] for line in out.splitlines() if line.startswith("KF-MAP"))
    covered = {tuple(map(int, line.split()[1:])) for line in out.splitlines() if line.startswith("KF-CELL")}
    # 20 mm/s is the third speed part of six from 5 to 300 mm/s (log), 250 mm/s the sixth; the
    # columns are 0.6 mm: 0..2.9 mm covers 0..4, 4.5..6 mm 7..9, 7..9 mm none (outside the area).
    assert covered == {(p, 2) for p in range(5)} | {(p, 5) for p in range(7, 10)}, out[-2000:]
    condition = session_folder.Condition(1, "c", paths.REPO_DIR, {}, (0, 6),
                                         events=[{"timeS": "1", "event": "coverageMap", "detail": detail}])
    cells = condition.live_cells()
    assert cells.shape == (10, 6) and {tuple(i) for i in np.argwhere(cells)} == covered
