"""The session folder's event names, one vocabulary for both sides: FrictionStudySession's
conditionEvents and sessionEvents (its log refuses any other name) are kfstudy.session_folder's
CONDITION_EVENTS and SESSION_EVENTS, and every name the Python side looks up is one of them."""
import re

from kfharness import paths, sclang
from kfstudy import session_folder


def test_sclang_and_python_name_the_same_events():
    out = sclang.run_script(r"""
"KF-CONDITION %".format(FrictionStudySession.conditionEvents.join(" ")).postln;
"KF-SESSION %".format(FrictionStudySession.sessionEvents.join(" ")).postln;
try { FrictionStudySession.checkEvent(\strat) } { |e| "KF-REFUSED %".format(e.what).postln };
try { FrictionStudySession.checkEvent(\prepare, true) } { |e| "KF-REFUSED-SESSION %".format(e.what).postln };
"KF-ACCEPTED % %".format(FrictionStudySession.checkEvent(\prepare), FrictionStudySession.checkEvent(\finish, true)).postln;
""", name="session-events")
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
