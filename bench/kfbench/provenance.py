"""Which code and machine measured a part: the commit (marked when the working tree had changes
to tracked files other than the bench's own outputs), the date, the machine, its processor and the cores' code path."""
import os
import platform
import subprocess

from .common import BENCH_DIR

REPO = BENCH_DIR.parent
OUTPUTS = ("bench/REPORT.md", "bench/results.json")  # and the plots: bench/*.png


def _git(*args):
    # Not stripped: a status line starts with its two status columns, the first often a space.
    return subprocess.run(["git", "-C", str(REPO), *args], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                          text=True).stdout


def commit():
    head = _git("rev-parse", "--short=12", "HEAD").strip() or "unknown"
    changed = [line[3:] for line in _git("status", "--porcelain", "--untracked-files=no").splitlines()]
    changed = [path for path in changed if path not in OUTPUTS and not (path.startswith("bench/") and path.endswith(".png"))]
    return head + (" with uncommitted changes" if changed else "")


def processor():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "?"


def stamp(date, core_path):
    """core_path: the cores' code path (portable / avx2) the run's scsynth and native benches took."""
    mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return {"commit": commit(), "date": date, "processor": processor(), "core_path": core_path,
            "machine": f"{os.cpu_count()} cores, {mem_gib:.0f} GiB, {platform.system()} {platform.release()}"}
