"""Background load as a busy desktop makes it: two CPU hogs at normal priority and a disk writer
(direct I/O, so it really reaches the disk), for the realtime tests, the bench and the soak. Each
process is stopped by its pid; the writer's file is bounded (256 MiB, written over and over).

    with BackgroundLoad():        # or: python3 -m kfharness.load -- COMMAND...
        ...
"""
import os
import subprocess
import sys

from . import paths, procs

HOG = "while :; do :; done"
# 256 x 1 MiB written with O_DIRECT and fsync, again and again, over one file.
WRITER = 'while :; do dd if=/dev/zero of="$1" bs=1M count=256 oflag=direct conv=fsync status=none; done'


def realtime_allowed():
    """Whether this user may run SCHED_FIFO threads (root, or an rtprio limit): `chrt -f 1 true`."""
    try:
        return subprocess.run(["chrt", "-f", "1", "true"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL).returncode == 0
    except OSError:
        return False


class BackgroundLoad:
    def __init__(self, cpu_hogs=2, disk_writer=True):
        self.cpu_hogs = cpu_hogs
        self.disk_writer = disk_writer
        self.procs = []
        self.file = paths.work_dir() / f"load-writer-{os.getpid()}.bin"

    def start(self):
        for _ in range(self.cpu_hogs):
            self.procs.append(subprocess.Popen(["sh", "-c", HOG], stdin=subprocess.DEVNULL))
        if self.disk_writer:
            self.procs.append(subprocess.Popen(["sh", "-c", WRITER, "writer", str(self.file)],
                                               stdin=subprocess.DEVNULL))
        return self

    def describe(self):
        return f"{self.cpu_hogs} CPU hogs" + (" and a disk writer (O_DIRECT, 256 MiB)" if self.disk_writer else "")

    def stop(self):
        for proc in self.procs:
            children = procs.descendants(proc.pid)  # before the shell goes: they would be orphans
            procs.stop_pid(proc.pid)  # first, so that its loop starts no new dd
            proc.wait()
            for pid in children:
                procs.stop_pid(pid)
        self.procs = []
        self.file.unlink(missing_ok=True)

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


def main(argv):
    """python3 -m kfharness.load [--hogs N] [--no-disk] -- COMMAND...: runs COMMAND under the load."""
    hogs, disk = 2, True
    while argv and argv[0] != "--":
        flag = argv.pop(0)
        if flag == "--hogs":
            hogs = int(argv.pop(0))
        elif flag == "--no-disk":
            disk = False
        else:
            raise SystemExit(f"unknown option {flag}")
    command = argv[1:]
    if not command:
        raise SystemExit(__doc__)
    with BackgroundLoad(hogs, disk) as load:
        print(f"== under load: {load.describe()}", flush=True)
        return subprocess.run(command).returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
