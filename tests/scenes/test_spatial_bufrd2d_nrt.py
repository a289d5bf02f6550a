"""SpatialBufRd2D rendered by scsynth -N: a matrix read along a line at an angle, a circle and a
raster, each crossing the matrix's borders, against the definition in double
(kfharness.reference.surface) at the positions the UGen was given, at 44.1 and 192 kHz."""
import numpy as np
import pytest
import soundfile

from kfharness import nrt, paths, reference

WIDTH, HEIGHT = 24, 18
SPM_X, SPM_Y, ORIGIN_X, ORIGIN_Y = 2.0, 1.5, -3.0, 4.0  # 12 x 12 mm from (-3, 4) mm


def matrix():
    """Values with no structure an interpolator could exploit, in [-1, 1]."""
    return np.random.default_rng(5).uniform(-1, 1, (HEIGHT, WIDTH))


# Paths in mm as sclang UGen expressions of time t (s), over 0.25 s: each starts or passes
# outside the matrix (x in [-3, 9], y in [4, 16] mm), so the fades and the silence are read too.
PATHS = {
    "line at 30 degrees": ("Sweep.ar(0, 60 * cos(pi / 6)) - 6", "Sweep.ar(0, 60 * sin(pi / 6)) + 3"),
    "circle": ("SinOsc.ar(3, pi / 2) * 7 + 3", "SinOsc.ar(3) * 7 + 10"),
    "raster": ("LFSaw.ar(20, 1) * 7.5 + 3", "(Sweep.ar(0, 20).floor * 1.5) + 2.5"),
}


@pytest.mark.parametrize("rate", [44100, 192000])
def test_2d_reads_along_paths_match_the_definition(rate):
    m = matrix()
    path = paths.work_dir() / "surface-24x18.wav"
    soundfile.write(str(path), m.ravel().astype(np.float32), 48000, subtype="FLOAT")  # row after row
    outs = []
    for x, y in PATHS.values():
        for mode in (1, 2, 4):
            outs.append(f"[x = {x}, y = {y}, SpatialBufRd2D.ar(0, x, y, {WIDTH}, {SPM_X}, {SPM_Y}, {ORIGIN_X}, "
                        f"{ORIGIN_Y}, {mode})]")
    channels = 3 * len(outs)
    data, _ = nrt.score_and_render(f"surface-paths-{rate}", f"""
        var def = SynthDef(\\surface, {{ var x, y; Out.ar(0, [{", ".join(outs)}].flat) }});
        score = Score([
            [0.0, ['/b_allocRead', 0, "{path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\surface, nil, 1000).newMsg],
            [0.25, ['/n_free', 1000]]]);
    """, sample_rate=rate, channels=channels)
    ran = slice(0, nrt.bundle_start_sample(0.25, rate))
    k = 0
    for name in PATHS:
        for mode in (1, 2, 4):
            x, y, got = (data[ran, 3 * k + i].astype(np.float64) for i in range(3))
            k += 1
            column, row = (x - ORIGIN_X) * SPM_X, (y - ORIGIN_Y) * SPM_Y
            want = reference.surface(m, column, row, mode)
            outside = ~((column > -1) & (column < WIDTH) & (row > -1) & (row < HEIGHT))
            # The path really crosses the border and the matrix.
            assert outside.any() and (~outside).sum() > 0.3 * len(x), name
            assert not got[outside].any(), f"{name}, mode {mode}: not silent outside the matrix"
            # Float kernels against double: 5.7e-7 measured at worst in tests/dsp (values in
            # [-1, 1]); the same bound as there.
            err = np.max(np.abs(got - want))
            assert err < 2e-6, f"{name}, mode {mode}: {err}"
