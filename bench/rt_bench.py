"""Realtime parts of the benchmarks (bench/run.py imports this): scsynth booted by sclang against
`jackd -d dummy` through the realtime test harness tests/realtime/rt.py (a JACK server of its own
per run, teardown by pid).

    e2e    a FrictionPilot synth on FrictionDevice.sim (device thread, realtime) for a while, then
           kfStatus: the 1 kHz loop's period, report-to-UGen and force-to-magnet latencies
    scale  voices of the pilot chain on one simulated device, added stepwise until JACK reports
           that scsynth did not finish a period in time (an xrun)
"""
import os
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_rt = None


def fill(template, **values):
    """sclang code with @name@ placeholders filled (sclang uses % itself)."""
    for k, v in values.items():
        template = template.replace(f"@{k}@", str(v))
    assert "@" not in re.sub(r'"[^"]*"', "", template), "unfilled placeholder"
    return template


def harness(extension_dir, work_dir):
    """tests/realtime/rt.py, pointed at this build's extension folder and a scratch folder."""
    global _rt
    if _rt is None:
        os.environ["KF_EXTENSION_DIR"] = str(extension_dir)
        os.environ["KF_TEST_WORK_DIR"] = str(work_dir)
        sys.path.insert(0, str(ROOT / "tests" / "realtime"))
        import rt  # noqa: E402
        _rt = rt
    return _rt


# ---------------------------------------------------------------------------------------------
# End to end: one pilot on the simulated device, then kfStatus.

E2E_CODE = r"""
var dev, pilot, hand;
// The hand pushes the puck back and forth over the pilot signal of mapping 1 (6 mm), 12 mm/s.
hand = FrictionHand.path(Array.fill(@cycles@ * 2 + 1, { |i| [i * 0.5, if(i.odd) { 6 } { 0 }] }));
// The pilot first, on slot 0 (empty: it reads zeros), so that every report finds a running UGen.
pilot = FrictionPilot(0, \mapping1).play;
s.sync;
0.5.wait;
dev = FrictionDevice.sim(s, 0, hand);
s.sync;
"KF-E2E-OPEN".postln;
@seconds@.wait;
"KF-E2E-CPU % %".format(s.peakCPU, s.avgCPU).postln;
dev.status;
s.sync;
0.3.wait;
pilot.free;
dev.close;
s.sync;
"""

STATUS_RE = re.compile(r"kfStatus 0: (loop period|report to UGen|force to magnet) p50 ([0-9.]+) ms, "
                       r"p99 ([0-9.]+) ms, max ([0-9.]+) ms \(n (\d+)\)")


def parse_status(output):
    out = {}
    for m in STATUS_RE.finditer(output):
        out[m.group(1)] = {"p50_ms": float(m.group(2)), "p99_ms": float(m.group(3)), "max_ms": float(m.group(4)),
                           "n": int(m.group(5))}
    m = re.search(r"kfStatus 0: (\w+), reports (\d+) .*frames (\d+),.*queue overflows (\d+)/(\d+)", output)
    if m:
        out["mode"] = m.group(1)
        out["reports"] = int(m.group(2))
        out["frames"] = int(m.group(3))
        out["overflows"] = [int(m.group(4)), int(m.group(5))]
    return out


def client_xruns(log_text):
    return log_text.count("was not finished")


def driver_xruns(log_text):
    return len(re.findall(r"JackTimedDriver::Process XRun", log_text))


def run_e2e(rt, seconds=10.0, sample_rate=48000, log=print):
    code = fill(E2E_CODE, cycles=int(seconds) + 2, seconds=seconds)
    with rt.JackServer(sample_rate=sample_rate) as jack:
        t = time.monotonic()
        run = rt.run_sclang(code, jack, timeout=seconds + 60, name="bench-e2e")
        jack_log = jack.log_path.read_text(errors="replace")
    if not run.ok:
        raise SystemExit(f"e2e run failed, log {run.log_path}:\n{run.output[-4000:]}")
    status = parse_status(run.output)
    for k in ("loop period", "report to UGen", "force to magnet"):
        if k not in status:
            raise SystemExit(f"e2e: no '{k}' line from kfStatus:\n{run.output[-4000:]}")
    m = re.search(r"KF-E2E-CPU ([0-9.e+-]+) ([0-9.e+-]+)", run.output)
    status["peak_cpu"], status["avg_cpu"] = (float(m.group(1)), float(m.group(2))) if m else (None, None)
    status["client_xruns"] = client_xruns(jack_log)
    status["driver_xruns"] = driver_xruns(jack_log)
    status["seconds"] = seconds
    status["wall_s"] = time.monotonic() - t
    log(f"e2e: loop period p50 {status['loop period']['p50_ms']:.3f} p99 {status['loop period']['p99_ms']:.3f} "
        f"max {status['loop period']['max_ms']:.3f} ms; report to UGen p99 {status['report to UGen']['p99_ms']:.3f} ms; "
        f"force to magnet p99 {status['force to magnet']['p99_ms']:.3f} ms; xruns {status['client_xruns']}")
    return status


# ---------------------------------------------------------------------------------------------
# Scale: voices until the first xrun.

# One voice: the pilot chain of FrictionPilot.ar without its FrictionOut (one per device is the
# rule): FrictionMouseIn (linear) -> SpatialBufRd (cubic) -> LoudnessToFriction, the audio delayed
# by the device's audioDelay (DelayL, 50 ms maximum, as FrictionPilot) to the output, the force
# added onto a bus. One FrictionOut at the tail commands the mean of the voices' forces.
SCALE_CODE = r"""
var dev, hand, buf, bus, group, outSynth, voices = List.new, jackLog = @jack_log@;
var countXruns, setVoices, measure, results = List.new, lo = 0, hi = nil, n, step = 0, ok;
var window = @window@, settle = @settle@, maxVoices = @max_voices@, deadline = Main.elapsedTime + @budget@;
// A window fails when JACK reports that scsynth did not finish more than this many periods.
var limit = (@xrun_fraction@ * window * s.sampleRate / 64).round.asInteger;
countXruns = {
	var text = File.readAllString(jackLog) ? "";
	[(text.findAll("was not finished") ? []).size, (text.findAll("JackTimedDriver::Process XRun") ? []).size]
};
SynthDef(\kfbVoice, { |bufnum = 0, spm = 4000, origin = 0, forceBus = 0|
	var mouse = FrictionMouseIn.ar(0, 0, 1);
	var audio = SpatialBufRd.ar(1, bufnum, mouse[0], spm, origin, 4);
	var force = LoudnessToFriction.ar(audio, 0.001, -30, 0, 0.14, 0.5, 1);
	Out.ar(forceBus, force);
	Out.ar(0, DelayL.ar(audio * 0.001, 0.05, 0.001));
}).add;
SynthDef(\kfbForceOut, { |forceBus = 0, voices = 1|
	FrictionOut.ar(0, In.ar(forceBus) / max(voices, 1));
}).add;
buf = FrictionPilot.loadSignal(s);
bus = Bus.audio(s, 1);
s.sync;
group = Group.head(s);
outSynth = Synth.after(group, \kfbForceOut, [\forceBus, bus.index, \voices, 1]);
hand = FrictionHand.path(Array.fill(600, { |i| [i * 0.5, if(i.odd) { 6 } { 0 }] }));
dev = FrictionDevice.sim(s, 0, hand);
s.sync;
1.0.wait;
setVoices = { |count|
	while { voices.size < count } {
		var i = voices.size;
		voices.add(Synth.head(group, \kfbVoice, [\bufnum, buf.bufnum, \spm, [4000, 500, 8][i % 3],
			\origin, 0, \forceBus, bus.index]));
		if(voices.size % 64 == 0) { s.sync };
	};
	while { voices.size > count } { voices.pop.free };
	outSynth.set(\voices, count);
	s.sync;
};
// Returns [client xruns, driver xruns, max peakCPU, mean avgCPU] of one window.
measure = {
	var x0, x1, peaks = List.new, avgs = List.new;
	settle.wait;
	x0 = countXruns.value;
	(window / 0.25).round.asInteger.do { 0.25.wait; peaks.add(s.peakCPU); avgs.add(s.avgCPU) };
	x1 = countXruns.value;
	[x1[0] - x0[0], x1[1] - x0[1], peaks.maxItem, avgs.mean]
};
// Doubling from 0 and 8 voices, then bisection between the last passing step and the first
// failing one; a failing window is measured again, and the step fails only if both do.
"KF-SCALE-LIMIT %".format(limit).postln;
n = 0;
while { Main.elapsedTime < deadline } {
	var r, r2, failed;
	setVoices.(n);
	r = measure.value;
	failed = r[0] > limit;
	if(failed) { r2 = measure.value; failed = r2[0] > limit } { r2 = nil };
	"KF-SCALE % % % % % % %".format(n, r[0], r[1], r[2], r[3], r2 !? { r2[0] } ? -1, r2 !? { r2[2] } ? -1).postln;
	if(failed) { hi = n } { lo = n };
	if(hi.isNil) {
		n = if(n == 0) { 8 } { n * 2 };
		if(n > maxVoices) { "KF-SCALE-CAP".postln; deadline = 0 };
	} {
		if(hi == 0 or: { (hi - lo) <= max(4, (lo * 0.05).round) }) { deadline = 0 } { n = ((lo + hi) / 2).round.asInteger };
	};
};
"KF-SCALE-RESULT % %".format(lo, hi ? -1).postln;
setVoices.(0);
dev.close;
s.sync;
"""


def run_scale(rt, sample_rate, window_s=2.0, settle_s=0.75, max_voices=8192, budget_s=150.0, realtime=True,
              xrun_fraction=0.01, log=print):
    # More nodes and real-time memory than the harness's defaults (one DelayL buffer per voice).
    wrapper = rt.WRAPPER
    patched = wrapper.replace("options.memSize = 65536;",
                              "options.memSize = 524288;\n\toptions.maxNodes = 32768;")
    assert patched != wrapper, "rt.WRAPPER changed: update bench/rt_bench.py"
    jack_server = realtime_jack_server(rt, sample_rate) if realtime else rt.JackServer(sample_rate=sample_rate)
    with jack_server as jack:
        code = fill(SCALE_CODE, jack_log=rt.sc_string(jack.log_path), window=window_s, settle=settle_s,
                    max_voices=max_voices, budget=budget_s, xrun_fraction=xrun_fraction)
        t = time.monotonic()
        rt.WRAPPER = patched
        try:
            run = rt.run_sclang(code, jack, timeout=budget_s + 90, name=f"bench-scale-{sample_rate}")
        finally:
            rt.WRAPPER = wrapper
    if not run.ok:
        raise SystemExit(f"scale run at {sample_rate} Hz failed, log {run.log_path}:\n{run.output[-4000:]}")
    steps = []
    for f in run.lines("KF-SCALE "):
        steps.append({"voices": int(f[0]), "client_xruns": int(f[1]), "driver_xruns": int(f[2]),
                      "peak_cpu": float(f[3]), "avg_cpu": float(f[4]),
                      "retry_client_xruns": int(float(f[5])), "retry_peak_cpu": float(f[6])})
    res = run.lines("KF-SCALE-RESULT ")
    if not res:
        raise SystemExit(f"scale run at {sample_rate} Hz: no result, log {run.log_path}:\n{run.output[-4000:]}")
    lo, hi = int(res[0][0]), int(res[0][1])
    out = {"sample_rate": sample_rate, "window_s": window_s, "settle_s": settle_s, "steps": steps,
           "realtime_jack": realtime, "xrun_fraction": xrun_fraction,
           "xrun_limit": int(run.lines("KF-SCALE-LIMIT ")[0][0]),
           "max_without_xrun": lo, "first_with_xrun": hi if hi >= 0 else None,
           "capped": bool(run.lines("KF-SCALE-CAP")), "wall_s": time.monotonic() - t}
    log(f"scale {sample_rate} Hz: {lo} voices without an xrun, first xrun at {out['first_with_xrun']} "
        f"({len(steps)} steps, {out['wall_s']:.0f} s)")
    return out


def realtime_jack_server(rt, sample_rate):
    """rt.JackServer, but jackd runs its and its clients' process threads with SCHED_FIFO
    priority (-R -P 70) instead of rt.py's -r (no realtime): how a performer runs it. Needs the
    right to realtime scheduling (root or an rtprio limit)."""

    class RealtimeJackServer(rt.JackServer):
        def start(self, timeout_s=20.0):
            log = open(self.log_path, "w")
            self.proc = rt.subprocess.Popen(
                ["jackd", "-n", self.name, "-R", "-P", "70", "-d", "dummy", "-r", str(self.sample_rate),
                 "-p", str(self.period), "-C", "2", "-P", "2"],
                stdin=rt.subprocess.DEVNULL, stdout=log, stderr=rt.subprocess.STDOUT, env=self.env)
            log.close()
            deadline = time.monotonic() + timeout_s
            while time.monotonic() < deadline:
                if self.proc.poll() is not None:
                    raise RuntimeError(f"jackd exited ({self.proc.returncode}):\n{self.log()}")
                probe = rt.subprocess.run(["jack_lsp"], stdin=rt.subprocess.DEVNULL, stdout=rt.subprocess.PIPE,
                                          stderr=rt.subprocess.STDOUT, env=self.env, timeout=10, text=True)
                if probe.returncode == 0 and "system:playback_1" in probe.stdout:
                    return self
                time.sleep(0.2)
            self.stop()
            raise RuntimeError(f"jackd did not come up in {timeout_s} s:\n{self.log()}")

    return RealtimeJackServer(sample_rate=sample_rate)
