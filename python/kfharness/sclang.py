"""Headless sclang: its environment, a language config with the extension's classes, and two ways
to run code: `run_script` (plain sclang, e.g. to write Scores) and `run_with_server` (a realtime
scsynth booted by sclang against a JACK server; see jack.py)."""
import os
import pathlib
import random
import re
import subprocess
import time

from . import paths, procs
from .jack_registry import registered_servers


def sc_string(text):
    """A Python str as an sclang string literal."""
    return '"' + str(text).replace("\\", "\\\\").replace('"', '\\"') + '"'


def environment(base=None):
    """What headless sclang needs: no display (offscreen Qt), Qt WebEngine without its sandbox (as
    root) and a private XDG_RUNTIME_DIR. Also Qt WebEngine without its zygote and GPU processes,
    which no test shows a page in: a start costs 0.9 CPU-s instead of 1.1 (3 x 3 starts of an empty
    script, every process of each counted by the kernel's process accounting), and the test command
    starts about 180."""
    env = dict(os.environ if base is None else base)
    runtime = paths.work_dir() / "xdg-runtime"
    runtime.mkdir(mode=0o700, parents=True, exist_ok=True)
    os.chmod(runtime, 0o700)
    env.update(QT_QPA_PLATFORM="offscreen", QTWEBENGINE_DISABLE_SANDBOX="1", XDG_RUNTIME_DIR=str(runtime))
    env.setdefault("QTWEBENGINE_CHROMIUM_FLAGS", "--no-zygote --disable-gpu")
    return env


def server_preload():
    """The libraries every server the harness starts gets in LD_PRELOAD (KF_SERVER_PRELOAD, e.g. the
    ASan and UBSan runtimes for a sanitized plugin, which an uninstrumented scsynth cannot load
    otherwise); empty: none. Only the server gets them, not sclang."""
    return os.environ.get("KF_SERVER_PRELOAD", "").strip()


def server_program_code():
    """sclang that makes Server.program (booted servers) and Score.program start scsynth at normal
    priority, with server_preload() if there is one. SuperCollider 3.13 boots scsynth from its
    SystemClock thread, SCHED_FIFO 1 where realtime is allowed, and every thread of the server but
    JACK's audio thread would inherit it: servers side by side then starve every normal thread
    (ARCHITECTURE.md, Tests and checks). JACK still runs the audio thread SCHED_FIFO, and the device
    threads ask for theirs."""
    libs = server_preload()
    preload = f"\"env LD_PRELOAD=\" ++ {sc_string(libs)}.shellQuote ++ \" " if libs else "\""
    return (f"Server.program = \"exec chrt --other 0 \" ++ {preload}scsynth\";\n"
            "Score.program = Server.program;\n")


def config(include_paths=None):
    """A language config (sclang -l) that adds the classes to the standard library; default: the
    extension folder's Classes."""
    include_paths = include_paths or [paths.extension_dir() / "Classes"]
    conf = paths.work_dir() / f"sclang_conf-{abs(hash(tuple(map(str, include_paths))))}.yaml"
    lines = "".join(f"    - {p}\n" for p in include_paths)
    conf.write_text(f"includePaths:\n{lines}excludePaths: []\npostInlineWarnings: false\n")
    return conf


def command(script, include_paths=None):
    """sclang running `script` with the classes (config), listening on a free UDP port of its own:
    at the default 57120 sclang tries ten ports up, and beside a second test command more sclangs
    than that ran at once, the next without networking ("Primitive '_GetLangPort' failed" as it
    booted its server; fresh clones 81 and 82)."""
    return ["sclang", "-u", str(procs.free_udp_port()), "-l", str(config(include_paths)), str(script)]


# The code is compiled by a fixed wrapper, so that a syntax error is reported and exits instead
# of leaving sclang waiting.
SCRIPT_WRAPPER = """var fn = File.readAllString(%(code)s).compile;
if(fn.isNil) { "KF-SCRIPT-SYNTAX-ERROR".postln; 1.exit } {
  %(program)s%(start)s{ fn.value; "KF-SCRIPT-OK".postln; 0.exit }.try { |error|
    error.reportError; "KF-SCRIPT-ERROR".postln; 1.exit }%(end)s };
"""


# What sclang posts when its class library did not compile (a syntax error in a class file, a class
# found twice, as when the extension is both linked and installed into the user's Extensions). It
# then runs no script and does not exit: it waits for input. The runners stop it at this line, with
# the reason, instead of at their timeout (the study job waited out its 530 s).
LIBRARY_FAILED = "Library has not been compiled successfully"


def library_failed(output):
    """The class library's errors as sclang posted them (every line from the first ERROR up to
    LIBRARY_FAILED), or None when the library compiled (or has not finished compiling)."""
    end = output.find(LIBRARY_FAILED)
    if end < 0:
        return None
    start = output.find("ERROR")
    return output[start if 0 <= start < end else 0:end + len(LIBRARY_FAILED)]


def _script_files(code, name):
    key = f"{name}-{os.getpid()}-{random.randrange(16 ** 6):06x}"
    code_path = paths.work_dir() / f"{key}.code.scd"
    code_path.write_text(code)
    return key, code_path


def run_script(code, timeout=120, expect_ok=True, include_paths=None, name="script", env=None, routine=False):
    """Runs `code` (synchronous sclang, no server) headless; returns its output. The code succeeds
    when it runs to the end; any error makes sclang exit 1 (an AssertionError when expect_ok).
    `env`: extra environment variables (a HOME of its own, say; None removes one). `routine`: the
    code runs in a Routine on AppClock (it may wait)."""
    key, code_path = _script_files(code, name)
    script = paths.work_dir() / f"{key}.scd"
    start, end = ("Routine { ", " }.play(AppClock)") if routine else ("", "")
    script.write_text(SCRIPT_WRAPPER % dict(code=sc_string(code_path), program=server_program_code(), start=start,
                                            end=end))
    run_env = environment()
    for name, value in (env or {}).items():
        if value is None:
            run_env.pop(name, None)
        else:
            run_env[name] = value
    log_path = paths.work_dir() / f"{key}.log"
    with open(log_path, "w") as log:
        proc = subprocess.Popen(command(script, include_paths),
                                stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, env=run_env)
        try:
            failed = wait_for_sclang(proc, log_path, timeout)
            timed_out = proc.poll() is None and not failed
        finally:
            procs.stop_pid(proc.pid, grace_s=2.0)
            proc.wait()
    out = log_path.read_text(errors="replace")
    assert not failed, f"sclang's class library did not compile:\n{failed[-4000:]}"
    if timed_out:
        raise subprocess.TimeoutExpired(proc.args, timeout, out)
    if expect_ok:
        assert "KF-SCRIPT-OK" in out and proc.returncode == 0, f"sclang failed:\n{out[-4000:]}"
    return out


# sclang posts this once its class library has compiled: from then on it runs the script.
LIBRARY_COMPILED = "*** Welcome to SuperCollider"


def wait_for_sclang(proc, log_path, timeout, on_poll=None):
    """Waits until sclang (`proc`, posting into `log_path`) ends, `timeout` s pass, or its class
    library fails: then returns the library's errors (library_failed), else None. The log is read
    every 0.1 s until the library has compiled; `on_poll()` is called at each poll."""
    deadline = time.monotonic() + timeout
    compiling = True
    while proc.poll() is None and time.monotonic() < deadline:
        if compiling:
            text = log_path.read_text(errors="replace")
            failed = library_failed(text)
            if failed:
                return failed
            compiling = LIBRARY_COMPILED not in text
        if on_poll is not None:
            on_poll()
        time.sleep(0.1)
    return None


class SclangRun:
    """The result of one sclang session with a server."""

    def __init__(self, output, returncode, scsynth_pid, log_path):
        self.output = output
        self.returncode = returncode
        self.scsynth_pid = scsynth_pid
        self.log_path = log_path

    @property
    def ok(self):
        return "KF-SCRIPT-OK" in self.output and self.returncode == 0

    def lines(self, tag):
        """The fields after `tag` on every line that starts with it. A tagged line that may meet
        the server's posts is best posted in one write, `"TAG %\\n".postf(...)`: sclang 3.13's
        postln writes the text, then the line break (seen with strace), and the server's output,
        which reaches the same log, can land between them: "KF-POS 0 0 0 0.0FrictionMouseIn: no
        device is open at index 0", then an empty line (two tests failed so in a fresh clone at
        4908f79)."""
        return [line[len(tag):].split() for line in self.output.splitlines() if line.startswith(tag)]

    def error_lines(self):
        return [line for line in self.output.splitlines() if line.startswith("ERROR")]


SERVER_WRAPPER = r"""
var fn = File.readAllString(%(code)s).compile;
if(fn.isNil) { "KF-SCRIPT-SYNTAX-ERROR".postln; 1.exit } {
	var options, finish;
%(program)s	Server.local.addr = NetAddr("127.0.0.1", %(port)d);
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
	options.device = "%(device)s";
%(options)s	KineticFriction.addPluginPath(options);
	// Quits the server if it runs, and exits once its process has ended (sclang has posted its
	// exit code; checked every 0.02 s), or 0.5 s after at the latest.
	finish = { |code|
		var waited = 0;
		if(s.serverRunning) { s.quit };
		AppClock.sched(0, {
			if(s.pid.isNil or: { waited >= 0.5 }) { code.exit; nil } { waited = waited + 0.02; 0.02 }
		});
	};
	// A last resort: never leave sclang running (the harness also kills it by pid).
	SystemClock.sched(%(timeout)f, { "KF-SCRIPT-TIMEOUT".postln; finish.(3); nil });
	// On AppClock, like code evaluated in the IDE: GUI (plot, scope, Window) works from it.
	Routine {
		var ok = false, period, waitedS = 0;
		try {
			// sclang sees the server up at its first status poll after scsynth is ready (0.22 s
			// here): polled every 0.7 s (the default) the boot took 1.8 s, every 0.05 s 0.6 s
			// (measured against jackd -d dummy). Only while booting: the scene runs as a user's.
			// A poll answered before the login is may send a second /notify, which scsynth
			// answers "already registered" (all is well, it says).
			period = s.aliveThreadPeriod;
			s.aliveThreadPeriod = 0.05;
			// Not bootSync: it waits for ever when scsynth ends while booting (its JACK client
			// refused: "couldn't activate jack client"), this ends with it. The process starts
			// within the first 5 s counted (this Routine's own waits: on a busy machine more).
			s.boot;
			while { s.serverRunning.not and: { s.pid.notNil or: { waitedS < 5 } } } {
				0.05.wait;
				waitedS = waitedS + 0.05;
			};
			if(s.serverRunning.not) { Error("scsynth ended while booting (its output above)").throw };
			s.aliveThreadPeriod = period;
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


def run_with_server(code, jack, timeout=120, name="script", port=None, include_paths=None, env=None,
                    server_options=None, booted=None, server_left_s=5.0, progress=None):
    """Runs `code` (sclang statements, evaluated in a Routine on AppClock: `.wait`, `s.sync` and
    GUI work) with `s` booted against `jack`. Returns an SclangRun; the scsynth and sclang
    processes are gone when it returns, whatever happened. `env`: extra environment variables;
    `server_options`: ServerOptions to set over the defaults, e.g. {"memSize": 524288};
    `booted`: a threading.Event, set once the server is up or the run is over (so that runs side
    by side can boot one after another); `server_left_s`: how long a server left running after
    sclang ended may take to go before it is stopped; `progress`: a tag, whose lines the script
    posts are printed as they come, without it (a long job's progress)."""
    assert jack.alive(), "jackd is not running"
    port = port or procs.free_udp_port()
    key, code_path = _script_files(code, name)
    script = paths.work_dir() / f"{key}.scd"
    script.write_text(SERVER_WRAPPER % dict(code=sc_string(code_path), port=port, rate=jack.sample_rate,
                                            period=jack.period, timeout=max(timeout - 10, 5), program=server_program_code(),
                                            device=f"{jack.name}:{jack.sc_client}",
                                            options="".join(f"\toptions.{k} = {v};\n"
                                                            for k, v in (server_options or {}).items())))
    log_path = paths.work_dir() / f"{key}.log"
    run_env = environment(jack.env)
    run_env.update(SC_JACK_DEFAULT_INPUTS="", SC_JACK_DEFAULT_OUTPUTS="")
    run_env.update(env or {})
    proc = None
    scsynth_pid = None
    known_children = set()
    printed = 0  # how much of the log the progress lines were taken from
    with open(log_path, "w+") as log:
        try:
            proc = subprocess.Popen(command(script, include_paths),
                                    stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                    env=run_env, cwd=paths.work_dir())
            def on_poll():
                nonlocal printed
                known_children.update(procs.descendants(proc.pid))
                if progress is None and (booted is None or booted.is_set()):
                    return
                text = log_path.read_text(errors="replace")
                if progress is not None:
                    whole = text[printed:text.rfind("\n") + 1]  # lines sclang has ended
                    printed += len(whole)
                    for line in whole.splitlines():
                        if line.startswith(progress):
                            print(line.removeprefix(progress).strip(), flush=True)
                if booted is not None and not booted.is_set() and "KF-SERVER-UP" in text:
                    booted.set()

            failed = wait_for_sclang(proc, log_path, timeout, on_poll)
            if failed:
                log.write("\nKF-HARNESS: sclang's class library did not compile (above); stopped\n")
            elif proc.poll() is None:
                known_children.update(procs.descendants(proc.pid))
                log.write("\nKF-HARNESS: sclang timed out; killed\n")
        finally:
            if proc is not None:
                procs.stop_pid(proc.pid, grace_s=2.0)
                proc.wait()
            log.flush()
            if booted is not None:
                booted.set()
            output = log_path.read_text(errors="replace")
            m = re.search(r"^KF-SCSYNTH-PID (\d+)", output, re.M)
            if m:
                scsynth_pid = int(m.group(1))
                known_children.add(scsynth_pid)
            # scsynth quits on /quit; give it a moment, then stop whatever is left, by pid.
            for pid in sorted(known_children):
                if not procs.wait_pid_gone(pid, server_left_s):
                    procs.stop_pid(pid)
            # A server that did not quit (a signal, a crash, killed here) leaves its shared memory
            # behind, 8 MB a server; nothing uses it once the server is gone.
            pathlib.Path(f"/dev/shm/SuperColliderServer_{port}").unlink(missing_ok=True)
    if "could not initialize audio" in output or "start audio failed" in output:
        # The server's JACK client was refused, or not activated (seen three times in fresh clones,
        # cause unknown): what JACK itself said is the evidence.
        said = [line for line in jack.log(100000).splitlines() if "XRun" not in line][-30:]
        output += f"\nKF-HARNESS: jackd {jack.name}'s log, its xruns left out:\n" + "\n".join(said)
        output += f"\nJACK's server registry: {registered_servers()}\n"
    if os.environ.get("KF_RT_KEEP_LOGS"):
        print(f"sclang log: {log_path}")
    return SclangRun(output, proc.returncode if proc else None, scsynth_pid, log_path)


def require_ok(run, what="sclang"):
    assert run.ok, f"{what} failed (rc {run.returncode}), log {run.log_path}:\n{run.output[-6000:]}"
    return run


def fill(template, **values):
    """sclang code with @name@ placeholders filled (sclang uses % itself)."""
    for k, v in values.items():
        template = template.replace(f"@{k}@", str(v))
    assert "@" not in re.sub(r'"[^"]*"', "", template), "unfilled placeholder"
    return template


def pids_file(name):
    """The file a script run by run_and_kill(name=name) writes "<sclang pid> <scsynth pid>" into."""
    return paths.work_dir() / f"{name}-pids.txt"


def run_and_kill(code, jack, ready, name="killed", timeout=120, server_options=None, wait_s=90, orphaned=None):
    """Runs `code` with a server (run_with_server) in a thread of its own and kills sclang and
    scsynth with SIGKILL, by pid, once ready() is true (a crash mid-session). `code` must write
    "<sclang pid> <scsynth pid>\\n" to pids_file(name). Returns the run; an AssertionError if
    ready() did not come within wait_s. With `orphaned`, only sclang is killed, and
    orphaned(scsynth_pid, quit) is called at once: the server plays on without its client until
    quit() (an orderly /quit, which closes its open files), or is stopped by pid 60 s later."""
    import signal
    import threading
    pids = pids_file(name)
    pids.unlink(missing_ok=True)
    port = procs.free_udp_port()
    result = {}
    thread = threading.Thread(target=lambda: result.update(run=run_with_server(
        code, jack, timeout=timeout, name=name, port=port, server_options=server_options,
        server_left_s=5.0 if orphaned is None else 60.0)))
    thread.start()
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline and not (written_lines(pids) and ready()):
        time.sleep(0.02)
    assert written_lines(pids) and ready(), f"{name}: what the kill waits for never came"
    sclang_pid, scsynth_pid = (int(v) for v in written_lines(pids).split())
    if orphaned is None:
        os.kill(scsynth_pid, signal.SIGKILL)
    os.kill(sclang_pid, signal.SIGKILL)
    try:
        if orphaned is not None:
            orphaned(scsynth_pid, lambda: _send_quit(port))
    finally:
        thread.join(90)
    return result["run"]


def written_lines(path):
    """The text of a file sclang writes with File.use, once whole ("" before): File.use makes the
    file before it writes, and sclang has no rename, so a file is whole once it ends with a line
    break (a harness that read it in between got no pids, a fresh clone at 1a6ef7c)."""
    try:
        text = path.read_text()
    except FileNotFoundError:
        return ""
    return text if text.endswith("\n") else ""


def _send_quit(port):
    """/quit to the server on `port` (UDP, as sclang sends it)."""
    import socket
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.sendto(b"/quit\0\0\0,\0\0\0", ("127.0.0.1", port))
