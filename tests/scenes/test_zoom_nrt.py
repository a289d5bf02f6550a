"""Live re-mapping without jumps (issue 14): SpatialBufRd with keep 1 zooms about the puck.

A simulated puck moves at 20 mm/s over a ramp signal (sample k holds k, read with linear
interpolation, so the output is the read index). samplesPerMm changes 500 -> 1000 at 1 s; with
keep 0 the read point jumps, with keep 1 the index step at the change is no larger than the
steps around it."""
import numpy as np

from kfharness import nrt

SR = 48000
FRAMES = 60000


def render_zoom(name, keep, change="['/n_set', 1000, \\spm, 1000]"):
    data, _ = nrt.score_and_render(name, f"""
        var dev = FrictionDevice.describeSim(0, FrictionHand.speeds([[20, 3]]));
        var def = SynthDef(\\{name}, {{ |spm = 500, origin = 0|
            var x = FrictionMouseIn.ar(0)[0];
            Out.ar(0, [SpatialBufRd.ar(1, 0, x, spm, origin, 2, {keep}), x]);
        }});
        score = Score([
            [0.0, dev.openMsg]]
            ++ FrictionPilot.loadSignalMsgs(0, (0..{FRAMES - 1})).collect {{ |m| [0.0, m] }}
            ++ [[0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\{name}, nil, 1000).newMsg],
            [1.0, {change}],
            [2.0, dev.closeMsg],
            [2.05, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=2)
    return data[:, 0].astype(np.float64), data[:, 1].astype(np.float64)


def step_at_change(index, t_change=1.0):
    steps = np.abs(np.diff(index))
    i = int(round(t_change * SR))
    at = steps[i - 64:i + 64].max()  # the block the change takes effect in
    around = np.concatenate([steps[i - 4800:i - 64], steps[i + 64:i + 4800]]).max()
    return at, around


def test_zoom_about_the_puck_keeps_the_read_index_continuous():
    index, x = render_zoom("zoomkeep", 1)
    at, around = step_at_change(index)
    print(f"KF-FIGURE zoom_keep_step_at_change_samples {at:.4f} around {around:.4f}")
    assert at <= around * 1.001 + 1e-3, (at, around)
    # ... and the zoom took effect: the index grows twice as fast after the change.
    t = np.arange(len(index)) / SR
    before = np.polyfit(t[(t > 0.6) & (t < 0.95)], index[(t > 0.6) & (t < 0.95)], 1)[0]
    after = np.polyfit(t[(t > 1.2) & (t < 1.9)], index[(t > 1.2) & (t < 1.9)], 1)[0]
    assert 1.9 < after / before < 2.1, (before, after)


def test_without_keep_the_read_point_jumps():
    index, x = render_zoom("zoomjump", 0)
    at, around = step_at_change(index)
    print(f"KF-FIGURE zoom_nokeep_step_at_change_samples {at:.1f} around {around:.4f}")
    assert at > 1000 * around


def test_an_origin_change_with_keep_keeps_the_sample_under_the_puck():
    index, x = render_zoom("originkeep", 1, change="['/n_set', 1000, \\origin, 5]")
    at, around = step_at_change(index)
    print(f"KF-FIGURE origin_keep_step_at_change_samples {at:.4f} around {around:.4f}")
    assert at <= around * 1.001 + 1e-3
