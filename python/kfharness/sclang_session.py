"""One headless sclang that runs many pieces of code, one after another, for a test process: each
sclang start compiles the whole class library and starts Qt WebEngine (about 0.8 CPU-s here), and
a scene test file writes up to a dozen Scores. Each piece is compiled on its own and runs in an
Environment of its own, so that its variables and `~names` do not reach the next; what it leaves in
class variables does (a FrictionDevice slot, a SynthDef in the library), so only code that depends
on nothing a fresh interpreter has and this one may not runs here: every Score nrt.score_and_render
writes, and the scene tests' checks of classes without a server (`run`); what needs an environment,
a HOME or a class library of its own still starts sclang of its own (sclang.run_script).

The protocol is files in a folder of the session's: the harness writes <n>.scd, then <n>.go; sclang,
polling every 10 ms on AppClock, runs it, posts its output between KF-REQUEST-BEGIN <n> and
KF-REQUEST-END <n> <status> (sclang flushes each line), and writes its status in <n>.done. Idle for IDLE_EXIT_S
it exits by itself (so a test process killed without clean-up leaves nothing running for
long). The harness does not send a piece that could meet that exit: after IDLE_EXIT_S / 2 without
one it starts a new sclang. Its idle time counts from a later moment than sclang's (it sees
<n>.done after sclang wrote it), but sclang counts 0.01 s a poll, and a poll takes at least that
long, so sclang's count is at most the harness's time plus the lag in seeing <n>.done: far from
IDLE_EXIT_S while the harness's is under half of it."""
import atexit
import subprocess
import threading
import time

from . import paths, procs, sclang

IDLE_EXIT_S = 60.0
POLL_S = 0.01

DAEMON = r"""
var dir = %(dir)s, n = 0, idle = 0;
"KF-SESSION-UP".postln;
Routine {
	loop {
		var go = dir +/+ "%%.go".format(n);
		if(File.exists(go)) {
			var fn, status;
			idle = 0;
			"KF-REQUEST-BEGIN %%".format(n).postln;
			fn = File.readAllString(dir +/+ "%%.scd".format(n)).compile;
			status = if(fn.isNil) { "syntax-error" } {
				{ Environment.new.use { fn.value }; "ok" }.try { |error| error.reportError; "error" }
			};
			"KF-REQUEST-END %% %%".format(n, status).postln;
			File.use(dir +/+ "%%.done".format(n), "w", { |file| file.write(status ++ "\n") });
			n = n + 1;
		} {
			idle = idle + %(poll)f;
			if(idle > %(idle)f) { "KF-SESSION-IDLE".postln; 0.exit };
		};
		%(poll)f.wait;
	}
}.play(AppClock);
"""


class SclangSession:
    """A running sclang that takes code through run(), started on first use; stop() ends it."""

    def __init__(self, name="session"):
        self.name = name
        self.proc = None
        self.count = 0
        self.idle_since = 0.0
        self.lock = threading.Lock()

    def _start(self):
        self.dir = paths.work_dir() / f"{self.name}-{time.monotonic_ns()}"
        self.dir.mkdir()
        script = self.dir / "daemon.scd"
        script.write_text(DAEMON % dict(dir=sclang.sc_string(self.dir), poll=POLL_S, idle=IDLE_EXIT_S))
        self.log_path = self.dir / "sclang.log"
        with open(self.log_path, "w") as log:
            self.proc = subprocess.Popen(sclang.command(script),
                                         stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                         env=sclang.environment(), cwd=self.dir)
        self.count = 0

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def run(self, code, timeout=120):
        """Runs `code` (synchronous sclang); returns what it posted. An AssertionError, with the
        output, when it did not compile or threw."""
        with self.lock:
            if self.alive() and time.monotonic() - self.idle_since > IDLE_EXIT_S / 2:
                self.stop()
            if not self.alive():
                self._start()
            try:
                return self._run(code, timeout)
            finally:
                self.idle_since = time.monotonic()

    def _run(self, code, timeout):
        n = self.count
        self.count += 1
        (self.dir / f"{n}.scd").write_text(code)
        (self.dir / f"{n}.go").touch()
        done = self.dir / f"{n}.done"
        deadline = time.monotonic() + timeout
        while not (status := sclang.written_lines(done).strip()):
            if self.proc.poll() is not None:
                raise AssertionError(f"sclang (session) ended ({self.proc.returncode}) during piece {n}:\n"
                                     f"{self._log()[-4000:]}")
            if n == 0 and (failed := sclang.library_failed(self._log())):
                self.stop()
                raise AssertionError(f"sclang (session): its class library did not compile:\n{failed[-4000:]}")
            if time.monotonic() > deadline:
                self.stop()
                raise AssertionError(f"sclang (session): piece {n} took over {timeout} s; stopped:\n"
                                     f"{self._log()[-4000:]}")
            time.sleep(POLL_S)
        output = self._piece_output(n)
        assert status == "ok", f"sclang (session) piece {n}: {status}:\n{output[-4000:]}"
        return output

    def _log(self):
        return self.log_path.read_text(errors="replace")

    def _piece_output(self, n):
        log = self._log()
        begin = log.find(f"KF-REQUEST-BEGIN {n}\n")
        end = log.find(f"KF-REQUEST-END {n} ", begin)
        return log[begin:end if end >= 0 else None]

    def stop(self):
        if self.proc is not None:
            procs.stop_pid(self.proc.pid, grace_s=2.0)
            self.proc.wait()
            self.proc = None


_shared = None


def shared():
    """This process's session, started on first use and stopped at its exit."""
    global _shared
    if _shared is None:
        _shared = SclangSession()
        atexit.register(_shared.stop)
    return _shared


def stop_shared():
    if _shared is not None:
        _shared.stop()


def run(code, timeout=120):
    """`code` run by this process's session: for code that, like a Score's, depends on nothing a
    fresh interpreter has and this one may not (see above)."""
    return shared().run(code, timeout)
