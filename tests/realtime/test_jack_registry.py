"""Killed jackds do not use up JACK's server registry.

JACK keeps 8 server slots and frees one only when its jackd exits normally or a server of the
same name starts. Every test server has a name of its own, so CI at 60f8359 (a test kills jackd
on purpose, a stop that times out kills one) filled the table, and every jackd after it failed
with "Too many servers already active": 22 realtime tests and the main job."""
import os
import signal

import pytest

from kfharness import jack, jack_registry
from kfharness.jack import JackServer


@pytest.fixture
def every_slot():
    """Every JACK server slot (jack.take_every_slot), one for the test's own server to take
    (slots.pop()): a second test command's jackd starting meanwhile would reclaim the dead entries
    the test makes and checks, or take the entry it counts on."""
    gate, slots = jack.take_every_slot()
    yield slots
    for fd in [gate] + slots:
        os.close(fd)


def killed_jackd(name):
    """A jackd that took a registry slot and was killed with SIGKILL (its slot left taken)."""
    proc, registered = jack_registry.start_registered(name)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert registered, f"{name} did not register"


def test_a_full_table_of_killed_servers_does_not_stop_the_next_one(every_slot):
    free_slots = jack_registry.MAX_SERVERS - len(jack_registry.registered_servers())
    names = [f"kfdead{os.getpid()}x{i}" for i in range(free_slots)]
    for name in names:
        killed_jackd(name)
    assert set(names) <= set(jack_registry.dead_servers())
    assert len(jack_registry.registered_servers()) == jack_registry.MAX_SERVERS

    with JackServer(slot=every_slot.pop()) as server:
        assert server.alive()
        taken = [name for _, _, name in jack_registry.registered_servers()]
        assert server.name in taken and not set(names) & set(taken), taken
    assert server.name not in [name for _, _, name in jack_registry.registered_servers()]


def test_a_server_killed_in_a_test_leaves_no_slot_behind(every_slot):
    server = JackServer(slot=every_slot.pop()).start()
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


def test_every_slot_is_taken_beside_servers_starting_one_after_another(tmp_path, monkeypatch):
    """take_every_slot closes the gate, then waits for each slot: a server starting after that
    waits, one that held a slot frees it, and the filler has them all. Beside a loop of servers
    that took slot 0 again as soon as it freed it, the filler without the gate waited as long as
    the loop ran (50 s); it gives up a slot held too long and lets go of those it took."""
    import threading
    import time
    monkeypatch.setattr(jack, "SLOT_LOCK", str(tmp_path / "slot-{}.lock"))
    stop, started = threading.Event(), []

    def servers_one_after_another():
        while not stop.is_set():
            fd = jack.take_slot(timeout_s=10.0)
            started.append(time.monotonic())
            time.sleep(0.05)
            os.close(fd)

    loop = threading.Thread(target=servers_one_after_another)
    loop.start()
    try:
        while not started:
            time.sleep(0.01)
        # The loop holds a slot 0.05 s at a time and the filler looks every 0.5 s: it has them all
        # in about 0.6 s with the gate, never without it; 5 s leaves a busy machine 8 times that.
        gate, every = jack.take_every_slot(timeout_s=5.0)
        filled = time.monotonic()
        assert len(every) == jack.SLOTS
        with pytest.raises(RuntimeError, match="no JACK server slot came free"):
            jack.take_slot(timeout_s=0)
        for fd in [gate] + every:
            os.close(fd)
        deadline = time.monotonic() + 5.0  # the loop looks every 0.5 s
        while started[-1] <= filled and time.monotonic() < deadline:
            time.sleep(0.05)
        assert started[-1] > filled, "the loop's servers did not go on after the filler"
    finally:
        stop.set()
        loop.join()

    held = jack.take_slot(timeout_s=0)
    with pytest.raises(RuntimeError, match="slot 0 did not come free"):
        jack.take_every_slot(timeout_s=1.0)
    rest = [jack.take_slot(timeout_s=0) for _ in range(jack.SLOTS - 1)]  # the gate open, the others free
    for fd in [held] + rest:
        os.close(fd)
