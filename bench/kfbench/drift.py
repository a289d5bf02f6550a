"""Drift: the loudness chains after a long NRT render (the first and last seconds recorded and
compared with equations (1) and (2)), and the Catch2 test that runs the LoudnessToFriction core
alone over 10^9 samples."""
import re
import subprocess
import time

from kfstudy import readers

from . import loudness, scores
from .common import LTF_N, SR, log

CAPTURE_S = 2.0
TEST_NAME = "no drift: 10^9 samples of white noise against a double recomputation"


def score_code(bench, minutes):
    return scores.code("drift", capture_s=CAPTURE_S, sample_rate=SR, total_s=minutes * 60.0,
                       first_wav=scores.sc_path(bench.work / "drift-first.wav"),
                       last_wav=scores.sc_path(bench.work / "drift-last.wav"),
                       osc=scores.sc_path(bench.work / "drift.osc"), **loudness.chain_values())


def analyse(bench, minutes):
    res = {"minutes": minutes}
    for which in ("first", "last"):
        data, rate = readers.read_wav(bench.work / f"drift-{which}.wav")
        assert rate == SR
        res[which], _ = loudness.errors(data, LTF_N)
    res["capture_s"] = CAPTURE_S
    return res


def run_test(bench):
    """The Catch2 test of the LoudnessToFriction core over 10^9 samples (n = 192, noise at about
    -18 dB, compared with a double recomputation every 10^8 samples); its INFO line holds the
    worst error. None when the tests are not built."""
    exe = bench.exe("tests", "dsp_tests")
    if not exe.exists():
        log(f"{exe} not built (KF_TESTS off): skipping the 10^9-sample drift test")
        return None
    t = time.monotonic()
    proc = subprocess.run([str(exe), TEST_NAME, "-s"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.monotonic() - t
    m = re.search(r"worst \|error\| ([-+0-9.eE]+) N", proc.stdout)
    if proc.returncode != 0 or not m:
        raise SystemExit(f"drift test failed ({proc.returncode}):\n{proc.stdout[-3000:]}")
    return {"worst_n": float(m.group(1)), "samples": 1_000_000_000, "wall_s": wall,
            "command": f"{bench.relative(exe)} \"{TEST_NAME}\" -s"}
