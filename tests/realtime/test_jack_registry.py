"""Killed jackds do not use up JACK's server registry.

JACK keeps 8 server slots and frees one only when its jackd exits normally or a server of the
same name starts. Every test server has a name of its own, so CI at 60f8359 (a test kills jackd
on purpose, a stop that times out kills one) filled the table, and every jackd after it failed
with "Too many servers already active": 22 realtime tests and the main job."""
import os
import signal

from kfharness import jack_registry
from kfharness.jack import JackServer


def killed_jackd(name):
    """A jackd that took a registry slot and was killed with SIGKILL (its slot left taken)."""
    proc, registered = jack_registry.start_registered(name)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert registered, f"{name} did not register"


def test_a_full_table_of_killed_servers_does_not_stop_the_next_one():
    free_slots = jack_registry.MAX_SERVERS - len(jack_registry.registered_servers())
    names = [f"kfdead{os.getpid()}x{i}" for i in range(free_slots)]
    for name in names:
        killed_jackd(name)
    assert set(names) <= set(jack_registry.dead_servers())
    assert len(jack_registry.registered_servers()) == jack_registry.MAX_SERVERS

    with JackServer() as server:
        assert server.alive()
        taken = [name for _, _, name in jack_registry.registered_servers()]
        assert server.name in taken and not set(names) & set(taken), taken
    assert server.name not in [name for _, _, name in jack_registry.registered_servers()]


def test_a_server_killed_in_a_test_leaves_no_slot_behind():
    server = JackServer().start()
    os.kill(server.proc.pid, signal.SIGKILL)  # as test_study_server_lost does
    server.proc.wait()
    assert server.name in jack_registry.dead_servers()
    server.stop()
    assert server.name not in [name for _, _, name in jack_registry.registered_servers()]


def test_a_server_waits_for_a_slot_when_other_test_commands_hold_them_all(tmp_path, monkeypatch):
    """Two test commands side by side asked JACK for more than its 8 servers (fresh clones 60 and
    61). A JackServer takes one of jack.SLOTS lock files first: with every slot held it waits, and
    it goes on once one is freed. (The slots here are files of this test's own, so that holding
    them all stops no other test's server.)"""
    import time
    from kfharness import jack
    monkeypatch.setattr(jack, "SLOT_LOCK", str(tmp_path / "slot-{}.lock"))
    held = [jack.take_slot(timeout_s=0) for _ in range(jack.SLOTS)]
    try:
        started = time.monotonic()
        try:
            jack.take_slot(timeout_s=1.0)
            raise AssertionError("a slot was taken while every one was held")
        except RuntimeError as error:
            assert "no JACK server slot came free" in str(error) and time.monotonic() - started >= 1.0
        os.close(held.pop())
        with JackServer() as server:
            assert server.alive() and server.slot is not None
        assert server.slot is None
    finally:
        for fd in held:
            os.close(fd)
