"""What every part shares: the renders' sample rate and block, the paper's numbers as the bench
uses them (all from kfharness.profile: profiles/paper.json is their one source), the bench's
folders, logging and number formatting."""
import math
import os
import tempfile
import time
from pathlib import Path

from kfharness import paths, profile

BENCH_DIR = Path(__file__).resolve().parents[1]
SR = 48000
BLOCK = 64
T0 = time.monotonic()
PARTS = ["build", "log", "timing", "spatial", "loudness", "drift", "reconstruction", "report_rate", "e2e", "rtload", "scale", "drive", "patterns", "texture_rate", "thresholds"]

PILOT = profile.pilot()
MAPPING = profile.mapping()
DEVICE = profile.device()
PILOT_FRAMES = PILOT["signalFrames"]
PILOT_PERIOD = PILOT["cycleFrames"]
MAPPINGS = [PILOT[f"mapping{k}SamplesPerMm"] for k in (1, 2, 3)]  # samples per mm, Table 1
LTF_N = round(SR * MAPPING["windowS"])  # equation (1)'s window in samples
# The device's slowest step (one count per report) and its fastest speed (the paper says 334).
SLOWEST_MM_PER_S = round(DEVICE["countMm"] * DEVICE["updateRateHz"], 1)
FASTEST_MM_PER_S = math.ceil(profile.max_speed_mm_per_s())
SPEEDS = [100, 100, FASTEST_MM_PER_S]  # mm/s the timing render's positions sweep at, per mapping
GRID_SPEEDS = [SLOWEST_MM_PER_S, 20, 100, FASTEST_MM_PER_S]  # the speeds of the error grid
GRID = [(spm, v) for spm in MAPPINGS for v in GRID_SPEEDS]
ORIGIN = 10.0  # mm, as a synth control in both readers
SPATIAL_S = 4.0
FORCE_FRAME_MS = DEVICE["forceFramePeriodS"] * 1e3
LOOP_HZ = round(1 / DEVICE["forceFramePeriodS"])

# The level sweep repeats every 1.2 s, the length of a timing phase's measured window, so that
# every phase sees the same share of samples inside the clip range (where a logarithm is taken).
LOUDNESS_IN_SC = "WhiteNoise.ar(LFTri.ar(1 / 1.2, 1).range(-40, 6).dbamp)"


def mapping_sc(mean_sc):
    """Equation (2) in built-in UGens, for a mean |a| in sclang."""
    lo, hi = MAPPING["loDb"], MAPPING["hiDb"]
    return f"{mean_sc}.ampdb.clip({lo}, {hi}).linlin({lo}, {hi}, {MAPPING['loForceN']}, {MAPPING['hiForceN']}, nil)"


def running_sum_chain_sc(in_sc):
    return mapping_sc(f"(RunningSum.ar({in_sc}.abs, {LTF_N}) / {LTF_N})")


def amplitude_chain_sc(in_sc):
    return mapping_sc(f"Amplitude.ar({in_sc}, 0.001, 0.001)")


def log(msg):
    print(f"[bench {time.monotonic() - T0:6.1f} s] {msg}", flush=True)


def fmt(x, digits=3):
    return f"{x:.{digits}g}"


class Bench:
    """The folders of one run: the build folder (its bench targets), the installed extension (the
    plugin and classes, as kfharness finds it) and the scratch folder (kfharness.paths.work_dir)."""

    def __init__(self, build_dir):
        self.build = Path(build_dir)
        self.work = paths.work_dir()
        self.extension = paths.extension_dir()
        # The bench's own UGen (KFBenchClock) is built into build/bench and not installed.
        self.include_paths = [self.extension / "Classes", BENCH_DIR / "classes"]
        self.plugin_dirs = [self.build / "bench"]

    def tests_enabled(self):
        return (cmake_cache_value(self.build, "KF_TESTS", "ON") or "ON").upper() in ("ON", "1", "TRUE", "YES")

    def exe(self, *parts):
        return self.build.joinpath(*parts)

    def relative(self, path):
        path = Path(path)
        return path.relative_to(paths.REPO_DIR) if path.is_relative_to(paths.REPO_DIR) else path


def cmake_cache_value(build_dir, key, default=None):
    cache = Path(build_dir) / "CMakeCache.txt"
    if cache.exists():
        for line in cache.read_text().splitlines():
            if line.startswith(key + ":"):
                return line.split("=", 1)[1]
    return default


def point_harness_at(build_dir, work_dir):
    """kfharness finds the extension folder and the scratch folder through KF_EXTENSION_DIR and
    KF_TEST_WORK_DIR: point them at this build's extension folder and the bench's scratch folder
    (unless the caller has set them)."""
    extension = cmake_cache_value(build_dir, "KF_EXTENSION_DIR")
    if extension and "KF_EXTENSION_DIR" not in os.environ:
        os.environ["KF_EXTENSION_DIR"] = extension
    if work_dir:
        os.environ["KF_TEST_WORK_DIR"] = str(work_dir)
    elif "KF_TEST_WORK_DIR" not in os.environ:
        os.environ["KF_TEST_WORK_DIR"] = tempfile.mkdtemp(prefix="kf-bench-")
