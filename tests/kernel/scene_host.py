"""The host's half of the kernel group's scene (tests/kernel/scene/test_pilot_scene.cpp): sclang
here, as a user runs it, against scsynth in the guest, reached through QEMU's user network (the
guest's UDP port 57110 forwarded to a port of this host). The guest drives the scene through the
host hook "scene": "start" starts sclang, "state" says whether it is "ready" (the hardware device
open, the board armed, the pilot playing), still "waiting", or "failed <why>"; "stop" makes it
free the synth, disarm and close the device, and answers "done" once sclang has exited."""
import subprocess
import time

from kfharness import paths, procs, sclang

SERIAL = "KF-GADGET-0001"  # the gadget board's (tests/kernel/guest/GadgetBoard.hpp)
MOUSE = "0627:0001"        # QEMU's USB mouse (its keyboard has the same IDs and is never listed as a mouse)
COUNT_MM = 0.125           # one count, one sample of the pilot signal at mapping 3 (8 samples per mm)
# The guest's one emulated CPU runs the audio at a fraction of real time (scene-scsynth.log's
# kfStatus: its frames against the time it was open), so FrictionOut's frames come in bursts far
# apart, and the device's 10 ms watchdog, there for a stuck audio thread, would turn the force
# off between them. The scene is about which force reaches the board, not when: 0.5 s.
WATCHDOG_S = 0.5
# sclang's hang guard for the whole scene: no shorter than the guest program's own guards
# (test_pilot_scene.cpp: 120 s for sclang to be ready, then five steps of two 30 s waits), which
# say which step hung. At 150 s it ended scenes that were slow, not hung: 186 s of a guest whose
# 10 s board stream ran at 0.6 set-points per ms (1.8 at earlier stops), and the scene's play took
# 11.7 to 73 s in runs that passed. A scene that hangs is still ended: by the guest program's
# guards, or by the whole guest run's 480 s limit (test_kernel_guest.HANG_GUARD_S), whichever first.
SCENE_TIMEOUT_S = 420

SCENE = r"""
var stopFile = @stopFile@, finish;
finish = { |code| "KF-SCENE-EXIT %".format(code).postln; code.exit };
SystemClock.sched(@timeoutS@, { "KF-SCENE-TIMEOUT".postln; finish.(3); nil });
Routine {
	var s, buffer, device, synth;
	try {
		s = Server.remote(\guest, NetAddr("127.0.0.1", @port@));
		Server.default = s;
		while { s.serverRunning.not } { 0.05.wait };
		s.sync;
		"KF-SCENE-CONNECTED".postln;
		buffer = FrictionPilot.loadSignal(s);
		s.sync;
		device = FrictionDevice.hardware(s, @mouse@, @serial@, (countMm: @countMm@, watchdogS: @watchdogS@));
		device.arm;
		SynthDef(\kfScene, { |bufnum|
			var p = FrictionPilot.ar(0, bufnum, FrictionPilot.mappings[\mapping3], 0, 1, 0.2);
			Out.ar(0, p[\delayedAudio] ! 2);
			Out.kr(0, [A2K.kr(p[\position]), A2K.kr(p[\force]), A2K.kr(p[\commandedForce])]);
		}).add;
		s.sync;
		synth = Synth(\kfScene, [\bufnum, buffer.bufnum]);
		s.sync;
		"KF-SCENE-READY".postln;
		while { File.exists(stopFile).not } { 0.05.wait };
		device.status;  // posted by scsynth: the guest reads it in its log
		s.sync;
		synth.free;
		s.sync;
		device.disarm;
		device.close;
		s.sync;
		"KF-SCENE-DONE".postln;
		finish.(0);
	} { |error|
		error.reportError;
		"KF-SCENE-ERROR".postln;
		finish.(1);
	};
}.play(AppClock);
"""


class SceneHost:
    """The hook's handler: GuestSpec(hooks={"scene": SceneHost(port, work_dir)})."""

    def __init__(self, port, work_dir):
        self.port = port
        self.work_dir = work_dir
        self.proc = None
        self.log_path = work_dir / "scene-sclang.log"
        self.stop_path = work_dir / "scene-stop"

    def __call__(self, argument):
        return {"start": self.start, "state": self.state, "stop": self.stop}.get(
            argument.strip(), lambda: f"failed unknown request {argument!r}")()

    def start(self):
        self.stop_path.unlink(missing_ok=True)
        script = self.work_dir / "scene.scd"
        script.write_text(sclang.fill(SCENE, stopFile=sclang.sc_string(self.stop_path), timeoutS=SCENE_TIMEOUT_S,
                                      port=self.port, mouse=sclang.sc_string(MOUSE),
                                      serial=sclang.sc_string(SERIAL), countMm=COUNT_MM, watchdogS=WATCHDOG_S))
        self.log = open(self.log_path, "w")
        self.proc = subprocess.Popen(sclang.command(script), stdin=subprocess.DEVNULL,
                                     stdout=self.log, stderr=subprocess.STDOUT, env=sclang.environment(),
                                     cwd=paths.work_dir())
        return "ok"

    def _output(self):
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""

    def state(self):
        output = self._output()
        if "KF-SCENE-READY" in output:
            return "ready"
        if self.proc is None or self.proc.poll() is not None or "KF-SCENE-ERROR" in output:
            return "failed " + " | ".join(output.splitlines()[-12:])
        time.sleep(0.2)  # the guest asks again at once: not faster than this
        return "waiting"

    def stop(self):
        self.stop_path.write_text("stop\n")
        try:
            self.proc.wait(60)
        except subprocess.TimeoutExpired:
            procs.stop_pid(self.proc.pid)
        self.log.close()
        output = self._output()
        return "done" if "KF-SCENE-DONE" in output else "failed " + " | ".join(output.splitlines()[-12:])

    def close(self):
        """Whatever happened in the guest, no sclang is left running."""
        if self.proc is not None and self.proc.poll() is None:
            procs.stop_pid(self.proc.pid)
