"""One screenshot of FrictionView for the main job: the pilot (mapping 2) on a simulated device in
realtime (JACK dummy driver, no sound card), its view on a virtual display (Xvfb), taken after
the hand has pushed the puck across the fragment, so the picture shows the signal on the surface,
the puck past it, and the speed and friction of the crossing.

It needs jackd, sclang and Xvfb; without them, or when anything fails, it writes nothing and
says why (the main job's renders do not depend on it).
"""
import shutil
from pathlib import Path

from kfharness import sclang
from kfharness.jack import JackServer
from kfharness.xvfb import Xvfb

# The hand holds at -10 mm, then pulls the puck across the fragment (10 .. 58 mm) at 40 mm/s.
SCRIPT = r"""
var dev, pilot, v, t0;
dev = FrictionDevice.sim(s, 0, FrictionHand.path([[0, -10], [1.5, -10], [4.5, 110], [10, 110]]));
pilot = FrictionPilot(dev, \mapping2, origin: 10).play;
s.sync;
v = pilot.view(bounds: Rect(40, 40, 1000, 700));
v.rangeMm = [-20, 120];
t0 = Main.elapsedTime;
while { v.positionMm < 75 and: { Main.elapsedTime - t0 < 20 } } { 0.05.wait };
0.3.wait;
v.paused = true;  // the window shows the last picture drawn: let it settle, then grab it
0.3.wait;
Image.fromWindow(v.window).write(@PATH@);
"KF-VIEW-SHOT % mm % frames\n".postf(v.drawn.positionMm, v.frameCount);
v.free; pilot.free; dev.close;
s.sync;
"""


def write_view_shot(out_dir, log=print):
    """Writes out_dir/view.png; returns its path, or None (and logs why) when it cannot."""
    missing = [tool for tool in ("jackd", "sclang", "Xvfb") if shutil.which(tool) is None]
    if missing:
        log(f"   view screenshot skipped: {', '.join(missing)} not found")
        return None
    path = Path(out_dir) / "view.png"
    path.unlink(missing_ok=True)
    try:
        with Xvfb() as display, JackServer() as jack:
            run = sclang.run_with_server(SCRIPT.replace("@PATH@", sclang.sc_string(path)), jack, name="view-shot",
                                         timeout=90, env=display.env())
    except (OSError, RuntimeError) as error:
        log(f"   view screenshot skipped: {error}")
        return None
    if not (run.ok and path.exists()):
        log(f"   view screenshot failed (log {run.log_path})")
        return None
    shot = run.lines("KF-VIEW-SHOT ")
    log(f"   view screenshot: {path} (puck at {shot[0][0] if shot else '?'} mm)")
    return path
