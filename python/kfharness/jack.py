"""A JACK server on the dummy driver: a real-time audio clock without a sound card."""
import fcntl
import os
import random
import subprocess
import sys
import time

from . import paths, procs
from .jack_registry import reclaim, reclaim_dead_servers, registered_servers
from .load import realtime_allowed

# JACK's registry holds 8 servers a machine (jack_registry.MAX_SERVERS): a ninth jackd exits with
# "Too many servers already active". One test command runs up to 4 at once (ctest's lanes), so two
# commands side by side could ask for 9 (fresh clones 60 and 61). Each JackServer first takes one of
# SLOTS lock files, one of the 8 left for a server of the user's own; flock frees a lock when its
# holder exits, however it exits.
SLOTS = 7
SLOT_LOCK = "/dev/shm/kf-jack-slot-{}.lock"
SLOT_WAIT_S = 900.0  # a realtime test holds its server for up to a few minutes, the help examples 10
# A test that fills JACK's registry takes every slot (take_every_slot), the gate first: while the
# gate is held, take_slot takes no slot, so that servers starting one after another cannot keep the
# filler waiting (a loop of servers did for 50 s, taking slot 0 again as soon as it freed it).
GATE = "gate"


def _lock_file(name):
    return os.open(SLOT_LOCK.format(name), os.O_RDONLY | os.O_CREAT, 0o644)


def _gate_closed():
    fd = _lock_file(GATE)
    try:
        return not procs.try_flock(fd, fcntl.LOCK_SH)
    finally:
        os.close(fd)


def take_slot(timeout_s=SLOT_WAIT_S):
    """The open lock file of a free slot (closing it frees the slot); waits for one, saying so."""
    deadline, said = time.monotonic() + timeout_s, False
    while True:
        if not _gate_closed():
            for i in range(SLOTS):
                fd = _lock_file(i)
                if procs.try_flock(fd):
                    return fd
                os.close(fd)
        if time.monotonic() > deadline:
            raise RuntimeError(f"no JACK server slot came free in {timeout_s:.0f} s (held by other tests)")
        if not said:
            print("kfharness: no JACK server slot is free (another test command?): waiting", file=sys.stderr)
            said = True
        time.sleep(0.5)


def take_every_slot(timeout_s=SLOT_WAIT_S):
    """(gate, slots): the open lock files of the gate and of every slot, for a test that fills
    JACK's registry: no other test's server starts (or reclaims the entries it fills) until they
    are closed. One taker at a time (the gate), so two cannot each hold part and wait for the
    other's; take_slot holds nothing while it waits."""
    deadline, taken = time.monotonic() + timeout_s, []
    try:
        for name in [GATE, *range(SLOTS)]:
            taken.append(_lock_file(name))
            while not procs.try_flock(taken[-1]):
                if time.monotonic() > deadline:
                    raise RuntimeError(f"JACK server slot {name} did not come free in {timeout_s:.0f} s")
                time.sleep(0.5)
    except BaseException:
        for fd in taken:
            os.close(fd)
        raise
    return taken[0], taken[1:]


class JackServer:
    """jackd -n <unique name> -d dummy -r <rate> -p <period>, in the background.

    Clients find it through JACK_DEFAULT_SERVER in `env`; JACK_NO_START_SERVER keeps them from
    starting a server of their own when this one is gone. By default jackd runs without realtime
    scheduling (-r), which needs no rights; `realtime_priority` (e.g. 70) runs its and its
    clients' process threads SCHED_FIFO, as a performer would (needs root or an rtprio limit)."""

    def __init__(self, sample_rate=48000, period=64, realtime_priority=None, slot=None):
        self.name = f"kfrt{os.getpid()}x{random.randrange(16 ** 6):06x}"
        # scsynth's JACK client name here (ServerOptions.device, kfharness.sclang): JACK names a
        # client's notification socket /dev/shm/jack_<client>_<uid>_0, whatever its server, so two
        # scsynths named SuperCollider that open at once on two servers take each other's socket,
        # and one fails: "NotifyAddClient new_client fails name = SuperCollider", "Connection reset
        # by peer" in jackd's log, "Cannot open SuperCollider client" in scsynth's (seen with
        # realtime tests side by side).
        self.sc_client = f"SuperCollider-{self.name}"
        self.sample_rate = sample_rate
        self.period = period
        self.realtime_priority = realtime_priority
        self.proc = None
        # The lock file descriptor of its slot while it runs: taken on start (take_slot), or one of
        # take_every_slot's handed over; closed when it stops.
        self.slot = slot
        self.log_path = paths.work_dir() / f"jackd-{self.name}.log"
        self.env = dict(os.environ)
        self.env.update(JACK_DEFAULT_SERVER=self.name, JACK_NO_START_SERVER="1",
                        JACK_NO_AUDIO_RESERVATION="1")

    def command(self):
        scheduling = ["-r"] if self.realtime_priority is None else ["-R", "-P", str(self.realtime_priority)]
        return ["jackd", "-n", self.name, *scheduling, "-d", "dummy", "-r", str(self.sample_rate),
                "-p", str(self.period), "-C", "2", "-P", "2"]

    def start(self, timeout_s=20.0):
        if self.slot is None:
            self.slot = take_slot()
        try:
            # A killed jackd's slot in JACK's 8-slot registry stays taken (jack_registry.py).
            reclaim_dead_servers()
            with open(self.log_path, "w") as log:
                self.proc = subprocess.Popen(self.command(), stdin=subprocess.DEVNULL, stdout=log,
                                             stderr=subprocess.STDOUT, env=self.env)
            return self._wait_up(timeout_s)
        except BaseException:  # not up, or interrupted meanwhile (Ctrl-C, a job's SIGTERM): not left running
            self.stop()
            raise

    def _wait_up(self, timeout_s):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"jackd exited ({self.proc.returncode}):\n{self.log()}\n"
                                   f"JACK's server registry (pid, uid, name): {registered_servers()}")
            probe = subprocess.run(["jack_lsp"], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, env=self.env, timeout=10, text=True)
            if probe.returncode == 0 and "system:playback_1" in probe.stdout:
                return self
            time.sleep(0.2)
        raise RuntimeError(f"jackd did not come up in {timeout_s} s:\n{self.log()}")

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def stop(self):
        if self.proc is None:
            self._free_slot()
            return
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                print(f"jackd {self.name} did not stop within 5 s of SIGTERM: killed", file=sys.stderr)
                self.proc.kill()
                self.proc.wait(5)
        if self.proc.returncode == -9:  # killed here or by a test: its registry slot stays taken
            reclaim(self.name)
        self.proc = None
        self._free_slot()

    def _free_slot(self):
        if self.slot is not None:
            os.close(self.slot)
            self.slot = None

    def log(self, tail_chars=3000):
        try:
            return self.log_path.read_text(errors="replace")[-tail_chars:]
        except OSError:
            return ""

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


PERFORMER_PRIORITY = 70  # jackd -R -P 70: scsynth's audio thread at 65, the device threads at 66


def performer_jack(**kwargs):
    """A JACK server as a performer runs it: realtime scheduling where this user may (root or an
    rtprio limit), else at normal priority."""
    return JackServer(realtime_priority=PERFORMER_PRIORITY if realtime_allowed() else None, **kwargs)
