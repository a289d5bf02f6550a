"""Renders of Scores with scsynth -N (or supernova -N: KF_NRT_SERVER=supernova) and the plugin
loaded."""
import os
import subprocess
import time

from . import paths, procs, sclang, sclang_session
from kfstudy import readers


def server():
    """The server that renders: scsynth, or what KF_NRT_SERVER names (supernova)."""
    return os.environ.get("KF_NRT_SERVER", "scsynth")


def bundle_start_sample(time_s, sample_rate=48000, block_size=64):
    """The first sample of the block in which the server runs a bundle stamped time_s. scsynth -N
    runs it before the block that holds time_s (at a block border, the block that starts there).
    supernova -N runs it one block later (time_s > 0): its logical clock, stepped by a block
    truncated to OSC time units, runs a bundle at the first block that starts at or after its
    stamp (measured: a synth at 0.5 s starts at sample 24064, under scsynth at 24000)."""
    block = int(time_s * sample_rate / block_size + 1e-9)
    if server() == "supernova" and time_s > 0:
        block += 1
    return block * block_size


def plugin_path(extra_dirs=()):
    """scsynth's -U: the system plugins, the extension's plugin folder, and any extra folders."""
    dirs = [paths.SYSTEM_PLUGIN_DIR, paths.extension_dir() / "plugins", *extra_dirs]
    return ":".join(str(d) for d in dirs)


def render(score_path, out_path, sample_rate=48000, channels=1, block_size=64, timeout=300,
           sample_format="float", memory_kb=65536, extra_args=(), plugin_dirs=()):
    """Renders an OSC score file; returns the server's output (an AssertionError if it failed)."""
    cmd = [server(), "-N", str(score_path), "_", str(out_path), str(sample_rate), "WAV", sample_format,
           "-o", str(channels), "-i", "0", "-z", str(block_size), "-U", plugin_path(plugin_dirs),
           "-m", str(memory_kb), *map(str, extra_args)]
    if server() == "supernova":
        # supernova -N names its shared memory after its UDP port (0 unless given; it binds none in
        # NRT) and replaces one of that name: two renders at once, as two scene tests make, failed
        # with "boost::interprocess::bad_alloc" (5 of 60 in 15 rounds of 4 at once; none with a
        # port each). A port no server holds, one per render.
        cmd += ["-u", str(procs.free_udp_port())]
    env = dict(os.environ)
    preload = sclang.server_preload()
    if preload:
        env["LD_PRELOAD"] = preload
    proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=timeout, text=True, errors="replace", env=env)
    failed = proc.returncode != 0 or "FAILURE" in proc.stdout or "not installed" in proc.stdout
    assert not failed, f"{server()} -N failed ({proc.returncode}):\n{proc.stdout[-4000:]}"
    return proc.stdout


def timed_render(*args, **kwargs):
    """render(), and how long it took in s."""
    t = time.monotonic()
    render(*args, **kwargs)
    return time.monotonic() - t


def score_and_render(name, score_code, sample_rate=48000, channels=1, **render_args):
    """score_code is sclang that leaves a Score in `score`; returns (frames x channels float32,
    scsynth output)."""
    score_path = paths.work_dir() / f"{name}.osc"
    wav_path = paths.work_dir() / f"{name}-render.wav"
    sclang_session.shared().run(f"var score;\n{score_code.strip().rstrip(';')};\n"
                                f"score.writeOSCFile({sclang.sc_string(score_path)});")
    log = render(score_path, wav_path, sample_rate, channels, **render_args)
    data, rate = readers.read_wav(wav_path)
    assert rate == sample_rate
    return data, log
