"""JACK's server registry: dead servers' entries, and freeing them through jackd itself.

jackd registers its name in one shared-memory table of 8 slots (/dev/shm/jack-shm-registry,
JACK2's common/shm.c) and frees the slot when it exits normally. A jackd killed with SIGKILL
(test_study_server_lost kills one on purpose; a stop that times out kills one too) leaves its
slot taken, and JACK reclaims a dead entry only for a server starting under the same name. Each
test's server has a name of its own, so eight such kills made every later jackd fail with "Too
many servers already active" (CI at 60f8359: every realtime test after the sanitized stage).
`reclaim_dead_servers` starts a jackd under each dead entry's name and stops it with SIGTERM: JACK's
own code, under its own lock, reclaims the slot and then frees it."""
import os
import re
import subprocess
import time
from pathlib import Path

from .procs import pid_alive

REGISTRY_PATH = Path("/dev/shm/jack-shm-registry")
MAX_SERVERS = 8  # JACK2 common/shm.h
HEADER_BYTES = 24  # magic, protocol, type, size, hdr_len, entry_len
ENTRY_NAME_RE = re.compile(rb"jack-(\d+):([^:\0]+):")


def registered_servers(path=REGISTRY_PATH):
    """[(pid, uid, name)] of the registry's taken slots; [] without a registry."""
    try:
        data = path.read_bytes()
    except OSError:
        return []
    if len(data) < HEADER_BYTES or data[:4] != b"KCAJ":
        return []
    header_len = int.from_bytes(data[16:20], "little")
    entry_bytes = (header_len - HEADER_BYTES) // MAX_SERVERS
    servers = []
    for slot in range(MAX_SERVERS):
        entry = data[HEADER_BYTES + slot * entry_bytes:HEADER_BYTES + (slot + 1) * entry_bytes]
        pid = int.from_bytes(entry[:4], "little")
        match = ENTRY_NAME_RE.match(entry[4:])
        if pid and match:
            servers.append((pid, int(match.group(1)), match.group(2).decode(errors="replace")))
    return servers


def dead_servers(path=REGISTRY_PATH):
    """Names of this user's registry entries whose jackd is gone."""
    return [name for pid, uid, name in registered_servers(path)
            if uid == os.getuid() and not pid_alive(pid)]


def start_registered(name, timeout_s=10.0):
    """(proc, registered): a small jackd on the dummy driver named `name`, once it holds a slot
    of the registry (registered False if it exited or took longer than timeout_s)."""
    proc = subprocess.Popen(["jackd", "-n", name, "-r", "-d", "dummy", "-r", "48000", "-p", "1024"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=dict(os.environ, JACK_NO_AUDIO_RESERVATION="1"))
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and proc.poll() is None:
        if any(pid == proc.pid for pid, _, _ in registered_servers()):
            return proc, True
        time.sleep(0.05)
    return proc, False


def reclaim(name, timeout_s=10.0):
    """Start jackd as `name` until it holds the slot, then stop it normally (which frees it)."""
    proc, _ = start_registered(name, timeout_s)
    proc.terminate()
    try:
        proc.wait(timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def reclaim_dead_servers():
    """Frees the slots of this user's dead jackds; returns their names."""
    names = dead_servers()
    for name in names:
        reclaim(name)
    return names
