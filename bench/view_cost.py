"""What FrictionView costs: CPU of scsynth and of sclang (which draws) with a playing pilot, for
PHASE_S seconds without the view, then PHASE_S seconds with it (its own window on Xvfb, 30
frames/s), then with 20 of its monitor synths and no drawing, measured from /proc/<pid>/stat (user + system time) and scsynth's own average load.

Usage: PYTHONPATH=python bench/view_cost.py   (after the build; needs jackd, sclang, Xvfb). Not part of
bench/run.py: a machine shared with other work makes these numbers noisy; run it alone.
"""
from kfharness import sclang
from kfharness.jack import JackServer
from kfharness.xvfb import Xvfb

PHASE_S = 10

SCRIPT = r"""
var dev, pilot, v, cpu, measure, hand, def, monitors;
cpu = { |pid|
	var fields = "cat /proc/%/stat".format(pid).unixCmdGetStdOut.split($)).last.split($ );
	(fields[12].asInteger + fields[13].asInteger) / 100  // utime + stime (fields 14, 15), in s
};
measure = { |name|
	var t0 = Main.elapsedTime, s0 = cpu.(s.pid), l0 = cpu.(thisProcess.pid), loads = List.new;
	@PHASE@.do { 1.wait; loads.add(s.avgCPU) };
	"KF-COST % % % % %\n".postf(name, Main.elapsedTime - t0, cpu.(s.pid) - s0, cpu.(thisProcess.pid) - l0, loads.mean);
};
// Back and forth across the fragment (10 .. 58 mm) for 60 s.
hand = FrictionHand.speeds(([[40, 1.5], [-40, 1.5]] ! 20).flatten(1));
dev = FrictionDevice.sim(s, 0, hand);
pilot = FrictionPilot(dev, \mapping2, origin: 10).play;
s.sync;
2.wait;
measure.("pilot");
v = pilot.view(bounds: Rect(40, 40, 1000, 700));
v.rangeMm = [-20, 120];
2.wait;
measure.("pilot+view");
"KF-FRAMES % %\n".postf(v.frameCount, v.timeS);
def = v.synth.defName;
v.free;
s.sync;
// The monitor synth alone, without drawing: 20 of them (their replies find no responder).
monitors = 20.collect { Synth.tail(RootNode(s), def) };
s.sync;
2.wait;
measure.("pilot+20monitors");
monitors.do(_.free); pilot.free; dev.close; s.sync;
"""


def main():
    with Xvfb() as display, JackServer() as jack:
        run = sclang.require_ok(sclang.run_with_server(SCRIPT.replace("@PHASE@", str(PHASE_S)), jack,
                                                       name="view-cost", timeout=120, env=display.env()))
    rows = {r[0]: [float(v) for v in r[1:]] for r in run.lines("KF-COST ")}
    print(f"{'':12} {'wall s':>7} {'scsynth cpu s':>14} {'sclang cpu s':>13} {'scsynth avgCPU %':>17}")
    for name, (wall, synth, lang, load) in rows.items():
        print(f"{name:12} {wall:7.1f} {synth:14.2f} {lang:13.2f} {load:17.2f}")
    a, b, c = rows["pilot"], rows["pilot+view"], rows["pilot+20monitors"]
    print(f"the view adds: scsynth {100 * (b[1] / b[0] - a[1] / a[0]):+.2f} % of a core, "
          f"sclang {100 * (b[2] / b[0] - a[2] / a[0]):+.1f} % of a core "
          f"(frames, server time: {run.lines('KF-FRAMES ')[0]})")
    print(f"one monitor synth (from 20, no drawing): scsynth {100 * (c[1] / c[0] - a[1] / a[0]) / 20:+.3f} % of a core")


if __name__ == "__main__":
    main()
