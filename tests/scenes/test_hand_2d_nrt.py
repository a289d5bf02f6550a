"""The simulated hand's 2D scripts rendered in NRT: a line at 30 degrees, a circle and a raster
move the simulated puck in x and y, FrictionMouseIn follows it on both axes, and SpatialBufRd2D
reads a matrix along the path as its definition in double (kfharness.reference.surface) gives at
the positions FrictionMouseIn output."""
import numpy as np
import pytest
import soundfile

from kfharness import nrt, paths, reference

SR = 48000
SIZE = 60  # 60 x 60 samples at 1 sample per mm from (-30, -30) mm
SCRIPTS = {  # name: (FrictionHand, seconds)
    "line": ("FrictionHand.line(30, 40, 80)", 0.8),           # 40 mm at 30 degrees, 80 mm/s
    "circle": ("FrictionHand.circle(15, 60, 1)", 1.8),        # r 15 mm at 60 mm/s: 1.57 s a turn
    "raster": ("FrictionHand.raster(20, 6, 3, 50)", 1.8),  # 3 rows of 20 mm over 6 mm, 50 mm/s: 1.32 s
}


def render():
    """One render, each script on a slot of its own: per script (matrix, x, y, read) while it ran."""
    m = np.random.default_rng(11).uniform(-1, 1, (SIZE, SIZE))
    path = paths.work_dir() / "hand2d-surface.wav"
    soundfile.write(str(path), m.ravel().astype(np.float32), SR, subtype="FLOAT")
    opens, outs = [], []
    for slot, (hand, seconds) in enumerate(SCRIPTS.values()):
        opens.append(f"[0.0, FrictionDevice.describeSim({slot}, {hand}).openMsg]")
        outs.append(f"{{ var m = FrictionMouseIn.ar({slot}, 0, 1); "
                    f"[m[0], m[1], SpatialBufRd2D.ar(1, m[0], m[1], {SIZE}, 1, 1, -30, -30, 4)] }}.value")
    longest = max(seconds for _, seconds in SCRIPTS.values())
    data, _ = nrt.score_and_render("hand2d", f"""
        var def = SynthDef(\\hand2d, {{ Out.ar(0, [{", ".join(outs)}].flat) }});
        score = Score([{", ".join(opens)},
            [0.0, ['/b_allocRead', 1, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\hand2d, nil, 1000).newMsg],
            [{longest}, ['/n_free', 1000]]]);
    """, channels=3 * len(SCRIPTS))
    out = {}
    for k, (name, (_, seconds)) in enumerate(SCRIPTS.items()):
        ran = slice(0, nrt.bundle_start_sample(seconds, SR))
        out[name] = (m, *(data[ran, 3 * k + i].astype(np.float64) for i in range(3)))
    return out


@pytest.fixture(scope="module")
def renders():
    return render()


@pytest.mark.parametrize("name", list(SCRIPTS))
def test_the_2d_scripts_move_the_puck_and_the_surface_is_read_along_them(renders, name):
    m, x, y, got = renders[name]
    # The surface under the puck: as the definition at the positions FrictionMouseIn gave (float
    # kernels against double: 5.7e-7 at worst in tests/dsp, values in [-1, 1]).
    want = reference.surface(m, x + 30, y + 30, 4)
    assert np.max(np.abs(got - want)) < 2e-6
    assert np.std(got) > 0.1, "the read does not vary along the path"
    # The path, from FrictionMouseIn (the puck lags the hand's spring; counts of 0.021 mm).
    end = len(x) - 1
    if name == "line":
        along = x * np.cos(np.pi / 6) + y * np.sin(np.pi / 6)
        off = -x * np.sin(np.pi / 6) + y * np.cos(np.pi / 6)
        assert along[end] > 25 and np.all(np.diff(along[::480]) >= -0.05), "not moving out along the line"
        # Off the line by the sensor's count steps on each axis at most (two counts, 0.042 mm).
        assert np.max(np.abs(off)) < 0.05
    elif name == "circle":
        r = np.hypot(x, y - 0)[len(x) // 3:]  # after the start-up from (15, 0)
        # Centre (0, 0): the puck cuts inside by the spring's lag along the tangent (7 mm at the
        # minimum force 0.14 N and 20 N/m: sqrt(15^2 - 7^2) = 13.3 mm), plus its dynamics.
        assert 10 < r.min() and r.max() < 15.2, (r.min(), r.max())
        assert y.min() < -8 and y.max() > 8 and x.min() < -8, "not around the circle"
    else:
        # 3 rows of 20 mm at y = 0, 3, 6 mm: out, back, out. The hand's spring (20 N/m, 7 mm of lag
        # at 0.14 N) smooths the corners of rows this short; measured at 0.5, 1.0 and 1.5 s:
        # x = 14.8, 5.2, 14.5 mm, y rising by steps to 4.96 mm (6 mm less the lag along y).
        at = {t: int(t * SR) for t in (0.5, 1.0, 1.5)}
        assert x[at[0.5]] > 12 and x[at[1.0]] < 7 and x[at[1.5]] > 12
        assert np.all(np.diff(y) >= 0) and 4.5 < y[end] < 6.0
