"""The gallery's picture of the 2D texture (FrictionPattern.texture2D): the simulated hand's raster
(rows 0.5 mm apart) over a texture of 0.25..1 cycles/mm, rendered by scsynth -N; the force felt
along the raster drawn over (x, y) beside the definition on a grid, so a reader sees a surface and
not a few stripes. Called by gallery_job.py as render(out_dir), which returns the summary's
markdown lines. Writes texture2D-raster.csv (kfharness.trace_csv) and texture2D-raster.png."""
import numpy as np

from kfharness import nrt, trace_csv
from kfharness import patterns as K

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SR = 48000
SIDE_MM, ROWS, SPEED = 16.0, 33, 150.0
SECONDS = 3.9  # (33 rows x 16 mm + 16 mm) / 150 mm/s = 3.63 s, and the start
LO_N, HI_N = 0.14, 0.5
BAND, SEED = (0.25, 1.0), 5
FIRM_HAND = "(handStiffnessNPerM: 2000, handDampingNSPerM: 20)"


def score():
    return f"""
        var dev = FrictionDevice.describeSim(0, FrictionHand.raster({SIDE_MM}, {SIDE_MM}, {ROWS}, {SPEED}), {FIRM_HAND});
        var def = SynthDef(\\texture2d, {{
            var m = FrictionMouseIn.ar(0);
            var f = FrictionPattern.texture2D(m[0], m[1], {BAND[0]}, {BAND[1]}, {SEED});
            Out.ar(0, [m[0], m[1], f, FrictionOut.ar(0, f)])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\texture2d, nil, 1000).newMsg],
            [{SECONDS}, ['/n_free', 1000]],
            [{SECONDS}, dev.closeMsg]]);
    """


def definition_grid(step_mm=0.1):
    """The definition (no travel) on a grid over the raster's square: level(x, y) in [0, 1]."""
    u = np.arange(0, SIDE_MM + step_mm / 2, step_mm)
    gx, gy = np.meshgrid(u, u)
    lo, hi = BAND
    total = np.zeros_like(gx)
    for fx, fy, phi in K.texture2d_components(lo, hi, SEED):
        total += np.sin(2 * np.pi * (fx * gx + fy * gy) + phi)
    return np.clip(0.5 + total / (6 * np.sqrt(K.TEXTURE_2D_COMPONENTS / 2)), 0, 1)


def render(out_dir):
    data, _ = nrt.score_and_render("gallery-texture2d", score(), sample_rate=SR, channels=4)
    end = min(len(data), trace_csv.end_sample(SECONDS, SR))
    x, y, requested, commanded = (data[:end, i].astype(np.float64) for i in range(4))
    reference = LO_N + (HI_N - LO_N) * K.texture2d(x, y, SR, BAND[0], BAND[1], SEED)
    r = dict(t=np.arange(end) / SR, sr=SR, x=x, y=y, requested=requested, commanded=commanded, reference=reference)
    trace_csv.write(out_dir / "texture2D-raster.csv", r, SECONDS, columns=[
        ("time_s", "t", "{:.4f}"), ("x_mm", "x", "{:.4f}"), ("y_mm", "y", "{:.4f}"),
        ("force_requested_n", "requested", "{:.6f}"), ("force_commanded_n", "commanded", "{:.6f}"),
        ("force_definition_n", "reference", "{:.6f}")], period_s=K.frame_samples(SR) / SR)

    fig, ax = plt.subplots(1, 2, figsize=(11, 5), sharex=True, sharey=True)
    grid = LO_N + (HI_N - LO_N) * definition_grid()
    ax[0].imshow(grid, extent=(0, SIDE_MM, 0, SIDE_MM), origin="lower", cmap="viridis", vmin=LO_N, vmax=HI_N)
    ax[0].set_title(f"definition, {BAND[0]:g}..{BAND[1]:g} cycles/mm, seed {SEED}")
    every = K.frame_samples(SR)  # one point per 1 ms frame
    # Squares about as tall as the rows are apart (0.5 mm: ~8 px here), so the rows make a surface.
    dots = ax[1].scatter(x[::every], y[::every], c=requested[::every], s=30, marker="s", linewidths=0,
                         cmap="viridis", vmin=LO_N, vmax=HI_N)
    ax[1].set_title(f"force along the raster ({ROWS} rows, {SPEED:g} mm/s)")
    for a in ax:
        a.set_xlabel("x (mm)")
        a.set_aspect("equal")
    ax[0].set_ylabel("y (mm)")
    fig.colorbar(dots, ax=ax, label="force (N)", shrink=0.8)
    fig.savefig(out_dir / "texture2D-raster.png", dpi=100)
    plt.close(fig)

    moving = np.hypot(np.diff(x), np.diff(y)) * SR > 0.5 * SPEED
    deviation = np.abs(requested - reference).max()
    return ["\n## The 2D texture under a raster (issue 27, items 1 and 3)\n",
            f"`FrictionPattern.texture2D(x, y, {BAND[0]:g}, {BAND[1]:g}, {SEED})` (32 plane waves) under "
            f"`FrictionHand.raster({SIDE_MM:g}, {SIDE_MM:g}, {ROWS}, {SPEED:g})` (rows 0.5 mm apart), the force "
            f"sent to the device. The puck covered x {x.min():.1f} .. {x.max():.1f} mm, y {y.min():.1f} .. "
            f"{y.max():.1f} mm at {np.mean(np.hypot(np.diff(x), np.diff(y))[moving]) * SR:.0f} mm/s while moving; "
            f"force {requested.min():.3f} .. {requested.max():.3f} N, largest deviation from the definition "
            f"recomputed in numpy from the rendered (x, y): {deviation:.2g} N.\n",
            "Files: `texture2D-raster.png` (the definition on a grid beside the force felt along the raster), "
            "`.csv`.\n"]
