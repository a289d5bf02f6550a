"""Processes by pid (every server a test starts is stopped by its pid), free UDP ports and locks
across test commands."""
import contextlib
import fcntl
import os
import random
import signal
import socket
import sys
import time
from pathlib import Path


def pid_alive(pid):
    """True while pid runs; a zombie counts as gone."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(") ", 1)[1][0] != "Z"
    except (OSError, IndexError):
        return False


def _children_by_parent():
    """Every process's direct children, by parent pid, from one reading of /proc (processes may
    end while it is read)."""
    children = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            fields = Path(f"/proc/{name}/stat").read_text().rsplit(") ", 1)[1].split()
        except (OSError, IndexError):
            continue
        children.setdefault(int(fields[1]), []).append(int(name))
    return children


# Linux lists each thread's children in /proc/<pid>/task/<tid>/children (CONFIG_PROC_CHILDREN,
# on in Debian's kernels); without it every process's parent is read from /proc instead.
_HAVE_CHILDREN_FILES = Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children").exists()


def _children_of(pid):
    kids = []
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return kids
    for task in tasks:
        try:
            kids.extend(int(kid) for kid in Path(f"/proc/{pid}/task/{task}/children").read_text().split())
        except OSError:
            continue
    return kids


def descendants(pid):
    """Every process below pid, from /proc. The harness asks 10 times a second while sclang runs:
    reading every process's parent again for each descendant (sclang, its server, Qt's helpers)
    took a fifth of a core in the help examples' runs, so each process's own list of children is
    read where the kernel keeps one, and /proc is read once per call where it does not."""
    if _HAVE_CHILDREN_FILES:
        children_of = _children_of
    else:
        children_of = _children_by_parent().get
    found, todo = [], [pid]
    while todo:
        for kid in children_of(todo.pop()) or []:
            if kid not in found:
                found.append(kid)
                todo.append(kid)
    return found


def finish_on_sigterm():
    """A job ended by SIGTERM (kill, timeout) or SIGHUP (its terminal closed) ends as Ctrl-C ends
    it: its finally blocks run, and the jackd, sclang and servers it started are stopped rather
    than left running (Python's default for both is to die at once). Once: a second signal during
    the clean-up would cut it short."""
    def finish(signum, frame):
        for sig in (signal.SIGTERM, signal.SIGHUP):
            signal.signal(sig, signal.SIG_IGN)
        raise SystemExit(128 + signum)
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, finish)


def stop_pid(pid, grace_s=5.0):
    """SIGTERM, then SIGKILL after grace_s; only the one process given."""
    if pid is None or not pid_alive(pid):
        return
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    if wait_pid_gone(pid, grace_s):
        return
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def wait_pid_gone(pid, timeout_s):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if not pid_alive(pid):
            return True
        time.sleep(0.05)
    return not pid_alive(pid)


def free_udp_port():
    for _ in range(50):
        port = random.randint(20000, 56000)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
        return port
    raise RuntimeError("no free UDP port")


def try_flock(fd, kind=fcntl.LOCK_EX):
    """Whether this open file took the lock (flock, not waiting)."""
    try:
        fcntl.flock(fd, kind | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False


@contextlib.contextmanager
def machine_lock(name):
    """Holds /dev/shm/<name>.lock (flock) for the block: one holder on the machine at a time, whichever
    test command it is in (ctest's RESOURCE_LOCK orders only its own tests); waits, saying so. The
    lock is freed however its holder exits."""
    fd = os.open(f"/dev/shm/{name}.lock", os.O_RDONLY | os.O_CREAT, 0o644)
    try:
        if not try_flock(fd):
            print(f"kfharness: {name} is held (another test command?): waiting", file=sys.stderr)
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)
