"""A virtual X display for GUI tests and screenshots: Xvfb on the first free display number,
stopped by its pid. With DISPLAY=<display> and QT_QPA_PLATFORM=xcb, sclang's Qt windows are real
X windows (offscreen Qt draws as well, but only a display shows what a user sees)."""
import shutil
import subprocess
import time
from pathlib import Path

from . import procs


class Xvfb:
    def __init__(self, first=50, size="1280x800x24"):
        self.first = first
        self.size = size
        self.proc = None
        self.display = None

    @staticmethod
    def available():
        return shutil.which("Xvfb") is not None

    def start(self, timeout_s=15.0):
        for number in range(self.first, self.first + 50):
            if Path(f"/tmp/.X{number}-lock").exists() or Path(f"/tmp/.X11-unix/X{number}").exists():
                continue
            # -dpi 96: Qt then draws at one image pixel per view pixel.
            proc = subprocess.Popen(["Xvfb", f":{number}", "-screen", "0", self.size, "-dpi", "96", "-nolisten", "tcp"],
                                    stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            deadline = time.monotonic() + timeout_s
            try:
                while time.monotonic() < deadline and proc.poll() is None:
                    if Path(f"/tmp/.X11-unix/X{number}").exists():
                        self.proc, self.display = proc, f":{number}"
                        return self
                    time.sleep(0.1)
            except BaseException:  # interrupted (Ctrl-C, a job's SIGTERM): not left running
                procs.stop_pid(proc.pid)
                raise
            procs.stop_pid(proc.pid)  # lost a race for the number, or did not come up: try the next
            proc.wait()
        raise RuntimeError(f"Xvfb did not start on any display :{self.first}..:{self.first + 49}")

    def env(self):
        """The environment sclang needs to open its windows on this display."""
        return dict(DISPLAY=self.display, QT_QPA_PLATFORM="xcb")

    def stop(self):
        if self.proc is not None:
            procs.stop_pid(self.proc.pid)
            self.proc.wait()
            self.proc = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
