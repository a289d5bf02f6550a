"""Drives headless sclang and scsynth -N for the scene tests.

sclang builds SynthDefs with the extension's classes and writes Scores; scsynth renders them
with the plugin loaded; the tests read the rendered files and check them against expectations
they compute themselves.
"""
import os
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import soundfile

EXTENSION_DIR = Path(os.environ.get("KF_EXTENSION_DIR", Path(__file__).resolve().parents[2] / "build" / "KineticFriction"))
SYSTEM_PLUGIN_DIR = "/usr/lib/SuperCollider/plugins"
TEST_DATA_DIR = Path(os.environ.get("KF_TEST_DATA_DIR", Path(__file__).resolve().parents[1] / "data"))
WORK_DIR = Path(os.environ.get("KF_TEST_WORK_DIR") or tempfile.mkdtemp(prefix="kf-scenes-"))
WORK_DIR.mkdir(parents=True, exist_ok=True)


def sclang_env():
    env = dict(os.environ)
    runtime = WORK_DIR / "xdg-runtime"
    runtime.mkdir(mode=0o700, parents=True, exist_ok=True)
    env.update(QT_QPA_PLATFORM="offscreen", QTWEBENGINE_DISABLE_SANDBOX="1", XDG_RUNTIME_DIR=str(runtime))
    return env


def sclang_config():
    """A language config that adds the extension's classes to the standard library."""
    conf = WORK_DIR / "sclang_conf.yaml"
    conf.write_text(f"includePaths:\n    - {EXTENSION_DIR / 'Classes'}\nexcludePaths: []\npostInlineWarnings: false\n")
    return conf


def run_sclang(code, timeout=120, expect_ok=True):
    """Runs `code` (synchronous sclang) headless; returns its output. The code succeeds when it
    runs to the end; any error makes sclang exit 1."""
    # The code is compiled by a fixed wrapper, so that a syntax error is reported and exits
    # instead of leaving sclang waiting.
    key = abs(hash(code))
    code_path = WORK_DIR / f"code-{key}.scd"
    code_path.write_text(code)
    script = WORK_DIR / f"script-{key}.scd"
    script.write_text(
        f"var fn = File.readAllString(\"{code_path}\").compile;\n"
        "if(fn.isNil) { \"KF-SCRIPT-SYNTAX-ERROR\".postln; 1.exit } {\n"
        "  { fn.value; \"KF-SCRIPT-OK\".postln; 0.exit }.try { |error|\n"
        "    error.reportError; \"KF-SCRIPT-ERROR\".postln; 1.exit } };\n"
    )
    proc = subprocess.run(
        ["sclang", "-l", str(sclang_config()), str(script)],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        env=sclang_env(), timeout=timeout, text=True, errors="replace",
    )
    out = proc.stdout
    if expect_ok:
        assert "KF-SCRIPT-OK" in out and proc.returncode == 0, f"sclang failed:\n{out[-4000:]}"
    return out


def render(score_path, out_path, sample_rate=48000, channels=1, block_size=64, timeout=300):
    """Renders an OSC score file with scsynth -N and the plugin; returns scsynth's output."""
    plugin_path = f"{SYSTEM_PLUGIN_DIR}:{EXTENSION_DIR / 'plugins'}"
    cmd = ["scsynth", "-N", str(score_path), "_", str(out_path), str(sample_rate), "WAV", "float",
           "-o", str(channels), "-i", "0", "-z", str(block_size), "-U", plugin_path, "-m", "65536"]
    proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=timeout, text=True, errors="replace")
    assert proc.returncode == 0, f"scsynth -N failed ({proc.returncode}):\n{proc.stdout[-4000:]}"
    return proc.stdout


def read_wav(path):
    data, rate = soundfile.read(str(path), dtype="float32", always_2d=True)
    return data, rate


def score_and_render(name, score_code, sample_rate=48000, channels=1, **render_args):
    """score_code is sclang that leaves a Score in `score`; returns (frames x channels, scsynth output)."""
    score_path = WORK_DIR / f"{name}.osc"
    wav_path = WORK_DIR / f"{name}-render.wav"
    run_sclang(f"var score;\n{score_code.strip().rstrip(';')};\nscore.writeOSCFile(\"{score_path}\");")
    log = render(score_path, wav_path, sample_rate, channels, **render_args)
    data, rate = read_wav(wav_path)
    assert rate == sample_rate
    return data, log


def zero_crossing_frequency(x, sample_rate):
    """Frequency from the mean spacing of rising zero crossings, located to a fraction of a sample."""
    x = np.asarray(x, dtype=np.float64)
    idx = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    crossings = idx + (-x[idx]) / (x[idx + 1] - x[idx])
    assert len(crossings) >= 3, "too few zero crossings"
    return sample_rate * (len(crossings) - 1) / (crossings[-1] - crossings[0])
