"""The harness's shared sclang (kfharness.sclang_session), which writes every scene's Score: each
piece's output is its own, a failing piece fails its test with sclang's error and leaves the next
one working, a piece's environment does not reach the next, and a session whose sclang is gone
starts again. And sclang whose class library did not compile (it then waits for input, running
nothing): the runner stops it with the library's errors rather than at its timeout."""
import shutil

import pytest

from kfharness import paths, sclang
from kfharness.sclang_session import SclangSession


@pytest.fixture
def session():
    s = SclangSession(name="session-test")
    yield s
    s.stop()


def test_each_piece_gets_its_own_output_and_environment(session):
    first = session.run('"piece one %".format(1 + 1).postln; ~left = 7;')
    second = session.run('"piece two sees %".format(~left).postln;')
    assert "piece one 2" in first and "piece two" not in first
    assert "piece two sees nil" in second and "piece one" not in second


def test_an_error_fails_its_piece_only(session):
    with pytest.raises(AssertionError, match=r"(?s)piece 0: error.*Message 'notAMethod' not understood"):
        session.run("1.notAMethod;")
    with pytest.raises(AssertionError, match="piece 1: syntax-error"):
        session.run("(1 + ;")
    assert "after 3" in session.run('"after %".format(1 + 2).postln;')


def test_a_session_whose_sclang_ended_starts_again(session):
    session.run("1;")
    first = session.proc.pid
    session.stop()
    assert "again" in session.run('"again".postln;')
    assert session.proc.pid != first


def test_a_class_library_that_does_not_compile_stops_the_run_with_its_errors(tmp_path):
    """The extension's classes twice (as when it is both linked and installed into a user's
    Extensions): the run ends with sclang's errors well before its timeout, which would raise
    TimeoutExpired instead (the study job once waited out 530 s so)."""
    twice = tmp_path / "Classes"
    shutil.copytree(paths.extension_dir() / "Classes", twice)
    with pytest.raises(AssertionError, match=r"(?s)class library did not compile.*duplicate Class found: '"):
        sclang.run_script('"never run".postln;', timeout=60, include_paths=[paths.extension_dir() / "Classes", twice])


def test_each_sclang_listens_on_a_port_of_its_own():
    """sclang at SC's default port tries 57120 and the nine above it: beside a second test command
    more sclangs than that ran at once, and the next had no networking (fresh clones 81 and 82).
    The harness gives each a free port of its own (sclang.command)."""
    output = sclang.run_script('"KF-LANG-PORT %".format(NetAddr.langPort).postln;')
    port = int(output.split("KF-LANG-PORT ")[1].split()[0])
    assert not 57120 <= port < 57130, f"sclang listens on {port}, one of SC's default ports"
