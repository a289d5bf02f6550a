"""Drives the realtime tests: a JACK server on the dummy driver, headless sclang booting scsynth
against it with the plugin, and teardown of every process by its id.

Each test gets its own JACK server (a unique server name) and its own scsynth UDP port, so a
crashed run does not block the next and ctest may run files side by side. Nothing here needs
an audio device or realtime scheduling.

Environment:
    KF_EXTENSION_DIR     the extension folder (default: <repo>/build/KineticFriction)
    KF_TEST_DATA_DIR     recorded device data (default: <repo>/tests/data)
    KF_TEST_WORK_DIR     where scripts, logs and recordings go (default: a new temp dir)
    KF_RT_KEEP_LOGS      set: print the log paths of every run
"""
import os
import random
import re
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path

REPO_DIR = Path(__file__).resolve().parents[2]
EXTENSION_DIR = Path(os.environ.get("KF_EXTENSION_DIR") or REPO_DIR / "build" / "KineticFriction")
TEST_DATA_DIR = Path(os.environ.get("KF_TEST_DATA_DIR") or REPO_DIR / "tests" / "data")
WORK_DIR = Path(os.environ.get("KF_TEST_WORK_DIR") or tempfile.mkdtemp(prefix="kf-realtime-"))
WORK_DIR.mkdir(parents=True, exist_ok=True)

SAMPLE_RATE = 48000
PERIOD = 64


# --- processes -------------------------------------------------------------------------------

def _pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    # A zombie counts as gone.
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(") ", 1)[1][0] != "Z"
    except (OSError, IndexError):
        return False


def _children(pid):
    """Direct children of pid, from /proc."""
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(") ", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


def descendants(pid):
    found, todo = [], [pid]
    while todo:
        for kid in _children(todo.pop()):
            if kid not in found:
                found.append(kid)
                todo.append(kid)
    return found


def stop_pid(pid, grace_s=5.0):
    """SIGTERM, then SIGKILL after grace_s; only the one process given."""
    if pid is None or not _pid_alive(pid):
        return
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    deadline = time.monotonic() + grace_s
    while time.monotonic() < deadline:
        if not _pid_alive(pid):
            return
        time.sleep(0.05)
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def wait_pid_gone(pid, timeout_s):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if not _pid_alive(pid):
            return True
        time.sleep(0.05)
    return not _pid_alive(pid)


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


# --- JACK ------------------------------------------------------------------------------------

class JackServer:
    """jackd -n <unique name> -r -d dummy -r 48000 -p 64, in the background.

    Clients find it through JACK_DEFAULT_SERVER in `env`; JACK_NO_START_SERVER keeps them from
    starting a server of their own when this one is gone."""

    def __init__(self, sample_rate=SAMPLE_RATE, period=PERIOD):
        self.name = f"kfrt{os.getpid()}x{random.randrange(16 ** 6):06x}"
        self.sample_rate = sample_rate
        self.period = period
        self.proc = None
        self.log_path = WORK_DIR / f"jackd-{self.name}.log"
        self.env = dict(os.environ)
        self.env.update(JACK_DEFAULT_SERVER=self.name, JACK_NO_START_SERVER="1",
                        JACK_NO_AUDIO_RESERVATION="1")

    def start(self, timeout_s=20.0):
        log = open(self.log_path, "w")
        self.proc = subprocess.Popen(
            ["jackd", "-n", self.name, "-r", "-d", "dummy", "-r", str(self.sample_rate),
             "-p", str(self.period), "-C", "2", "-P", "2"],
            stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, env=self.env)
        log.close()
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"jackd exited ({self.proc.returncode}):\n{self.log()}")
            probe = subprocess.run(["jack_lsp"], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, env=self.env, timeout=10, text=True)
            if probe.returncode == 0 and "system:playback_1" in probe.stdout:
                return self
            time.sleep(0.2)
        self.stop()
        raise RuntimeError(f"jackd did not come up in {timeout_s} s:\n{self.log()}")

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def stop(self):
        if self.proc is None:
            return
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        self.proc = None

    def log(self):
        try:
            return self.log_path.read_text(errors="replace")[-3000:]
        except OSError:
            return ""

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


# --- sclang ----------------------------------------------------------------------------------

def sclang_config():
    conf = WORK_DIR / "sclang_conf.yaml"
    conf.write_text(f"includePaths:\n    - {EXTENSION_DIR / 'Classes'}\nexcludePaths: []\n"
                    "postInlineWarnings: false\n")
    return conf


def sc_string(text):
    """A Python str as an sclang string literal."""
    return '"' + str(text).replace("\\", "\\\\").replace('"', '\\"') + '"'


class SclangRun:
    """The result of one sclang session."""

    def __init__(self, output, returncode, scsynth_pid, log_path):
        self.output = output
        self.returncode = returncode
        self.scsynth_pid = scsynth_pid
        self.log_path = log_path

    @property
    def ok(self):
        return "KF-SCRIPT-OK" in self.output and self.returncode == 0

    def lines(self, tag):
        """The fields after `tag` on every line that starts with it."""
        return [line[len(tag):].split() for line in self.output.splitlines() if line.startswith(tag)]

    def error_lines(self):
        return [line for line in self.output.splitlines() if line.startswith("ERROR")]


WRAPPER = r"""
var fn = File.readAllString(%(code)s).compile;
if(fn.isNil) { "KF-SCRIPT-SYNTAX-ERROR".postln; 1.exit } {
	var options, finish;
	Server.local.addr = NetAddr("127.0.0.1", %(port)d);
	Server.default = s = Server.local;
	options = s.options;
	options.sampleRate = %(rate)d;
	options.blockSize = 64;
	options.hardwareBufferSize = %(period)d;
	options.numInputBusChannels = 2;
	options.numOutputBusChannels = 2;
	options.memSize = 65536;
	options.maxLogins = 4;
	options.bindAddress = "127.0.0.1";
	KineticFriction.addPluginPath(options);
	finish = { |code|
		if(s.serverRunning) { s.quit };
		AppClock.sched(0.5, { code.exit; nil });
	};
	// A last resort: never leave sclang running (the harness also kills it by pid).
	SystemClock.sched(%(timeout)f, { "KF-SCRIPT-TIMEOUT".postln; finish.(3); nil });
	// On AppClock, like code evaluated in the IDE: GUI (plot, scope, Window) works from it.
	Routine {
		var ok = false;
		try {
			s.bootSync;
			"KF-SCSYNTH-PID %%".format(s.pid).postln;
			s.sync;
			"KF-SERVER-UP".postln;
			fn.value;
			ok = true;
		} { |error|
			error.reportError;
			"KF-SCRIPT-ERROR".postln;
		};
		if(ok) { "KF-SCRIPT-OK".postln; finish.(0) } { finish.(1) };
	}.play(AppClock);
};
"""


def run_sclang(code, jack, timeout=120, name="script", port=None, extra_env=None):
    """Runs `code` (sclang statements, evaluated in a Routine on AppClock: `.wait`, `s.sync`
    and GUI work) with
    `s` booted against `jack`. Returns an SclangRun; the scsynth and sclang processes are gone
    when it returns, whatever happened. extra_env: variables set last (e.g. DISPLAY and
    QT_QPA_PLATFORM=xcb for a virtual display instead of offscreen)."""
    assert jack.alive(), "jackd is not running"
    port = port or free_udp_port()
    key = f"{name}-{os.getpid()}-{random.randrange(16 ** 6):06x}"
    code_path = WORK_DIR / f"{key}.code.scd"
    code_path.write_text(code)
    script = WORK_DIR / f"{key}.scd"
    script.write_text(WRAPPER % dict(code=sc_string(code_path), port=port, rate=jack.sample_rate,
                                     period=jack.period, timeout=max(timeout - 10, 5)))
    log_path = WORK_DIR / f"{key}.log"
    env = dict(jack.env)
    runtime = WORK_DIR / "xdg-runtime"
    runtime.mkdir(mode=0o700, parents=True, exist_ok=True)
    env.update(QT_QPA_PLATFORM="offscreen", QTWEBENGINE_DISABLE_SANDBOX="1",
               XDG_RUNTIME_DIR=str(runtime), SC_JACK_DEFAULT_INPUTS="", SC_JACK_DEFAULT_OUTPUTS="")
    env.update(extra_env or {})
    proc = None
    scsynth_pid = None
    known_children = set()
    with open(log_path, "w+") as log:
        try:
            proc = subprocess.Popen(["sclang", "-l", str(sclang_config()), str(script)],
                                    stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                    env=env, cwd=WORK_DIR)
            deadline = time.monotonic() + timeout
            while proc.poll() is None and time.monotonic() < deadline:
                known_children.update(descendants(proc.pid))
                time.sleep(0.1)
            if proc.poll() is None:
                known_children.update(descendants(proc.pid))
                log.write("\nKF-HARNESS: sclang timed out; killed\n")
        finally:
            if proc is not None:
                stop_pid(proc.pid, grace_s=2.0)
                proc.wait()
            log.flush()
            output = log_path.read_text(errors="replace")
            m = re.search(r"^KF-SCSYNTH-PID (\d+)", output, re.M)
            if m:
                scsynth_pid = int(m.group(1))
                known_children.add(scsynth_pid)
            # scsynth quits on /quit; give it a moment, then stop whatever is left, by pid.
            for pid in sorted(known_children):
                if not wait_pid_gone(pid, 5.0):
                    stop_pid(pid)
    if os.environ.get("KF_RT_KEEP_LOGS"):
        print(f"sclang log: {log_path}")
    return SclangRun(output, proc.returncode if proc else None, scsynth_pid, log_path)


def require_ok(run, what="sclang"):
    assert run.ok, f"{what} failed (rc {run.returncode}), log {run.log_path}:\n{run.output[-6000:]}"
    return run


# --- kf-session files ------------------------------------------------------------------------

def read_session(path):
    """(header dict, [(tag, [floats])...]) of a kf-session file."""
    lines = Path(path).read_text().splitlines()
    assert lines and lines[0].startswith("kf-session 1 "), f"not a kf-session file: {path}"
    header = dict(field.split("=", 1) for field in lines[0].split()[2:])
    records = []
    for line in lines[1:]:
        if not line.strip() or line.startswith("#"):
            continue
        tag, *fields = line.split()
        records.append((tag, [float(f) for f in fields]))
    return header, records
