"""The gallery's part for 2D surfaces and friction that steers (issue 27, items 3 to 5), called by
gallery_job.py as render(out_dir), which returns the summary's markdown lines. Rendered by
scsynth -N on simulated devices, one slot per case, in one Score:
- a data map (a 6 x 4 table, 8 mm a cell) scanned row by row by the hand's raster: SpatialBufRd2D
  gives the sound's value (linear) and the friction (cell by cell);
- SpeedGovernor against a hand pushing with 0.25 N, beside the resting force alone.
Writes surfaces-data-map.csv/.png and steering-governor.csv/.png (CSVs by kfharness.trace_csv)."""
import numpy as np
import soundfile

from kfharness import nrt, paths, trace_csv

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SR = 48000
SECONDS = 5.8  # the raster: (4 rows x 48 mm + 24 mm) / 40 mm/s = 5.4 s
DATA = np.array([[2, 3, 5, 4, 3, 2], [3, 6, 9, 7, 4, 2], [2, 5, 8, 9, 6, 3], [1, 2, 4, 5, 4, 2]], dtype=float)
CELL_MM = 8.0
LO_N, HI_N, MAP_HI_N = 0.14, 1.4, 0.8
PUSH_N, TARGET, GAIN = 0.25, 80.0, 0.01
# The map's hand is firm (as the pattern gallery's): the default hand (20 N/m) needs 40 mm of lag to
# push through 0.8 N, more than a row of cells.
FIRM_HAND = "(handStiffnessNPerM: 2000, handDampingNSPerM: 20)"


def score(map_path):
    width = DATA.shape[1]
    spm = 1 / CELL_MM
    return f"""
        var map = FrictionDevice.describeSim(0, FrictionHand.raster(48, 24, 4, 40, 0, 4), {FIRM_HAND});
        var free = FrictionDevice.describeSim(1, FrictionHand.force({PUSH_N}));
        var governed = FrictionDevice.describeSim(2, FrictionHand.force({PUSH_N}));
        var def = SynthDef(\\surfaces, {{
            var m0 = FrictionMouseIn.ar(0, 0, 1), m1 = FrictionMouseIn.ar(1, 0, 1), m2 = FrictionMouseIn.ar(2, 0, 1);
            var value = SpatialBufRd2D.ar(1, m0[0], m0[1], {width}, {spm}, {spm}, 0, 0, 2);
            var cell = SpatialBufRd2D.ar(1, m0[0], m0[1], {width}, {spm}, {spm}, 0, 0, 1);
            Out.ar(0, [m0[0], m0[1], value, FrictionOut.ar(0, cell.linlin(0, 1, {LO_N}, {MAP_HI_N})),
                m1[0], m1[2], FrictionOut.ar(1, DC.ar({LO_N})),
                m2[0], m2[2], FrictionOut.ar(2, SpeedGovernor.ar(m2[2], m2[3], {TARGET}, {GAIN}, {LO_N}, {HI_N}))])
        }});
        score = Score([map, free, governed].collect {{ |d| [0.0, d.openMsg] }} ++ [
            [0.0, ['/b_allocRead', 1, "{map_path}"]],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\surfaces, nil, 1000).newMsg],
            [{SECONDS}, ['/n_free', 1000]]]);
    """


def render(out_dir):
    normalised = (DATA - DATA.min()) / (DATA.max() - DATA.min())
    map_path = paths.work_dir() / "gallery-data-map.wav"
    soundfile.write(str(map_path), normalised.ravel().astype(np.float32), SR, subtype="FLOAT")
    data, _ = nrt.score_and_render("gallery-surfaces", score(map_path), channels=10)
    t = np.arange(len(data)) / SR
    ch = {name: data[:, i].astype(np.float64) for i, name in enumerate(
        ["x", "y", "value", "map_force", "free_x", "free_speed", "free_force", "gov_x", "gov_speed", "gov_force"])}
    r = dict(ch, t=t, sr=SR)
    trace_csv.write(out_dir / "surfaces-data-map.csv", r, SECONDS, columns=[
        ("time_s", "t", "{:.4f}"), ("x_mm", "x", "{:.4f}"), ("y_mm", "y", "{:.4f}"),
        ("value_0_1", "value", "{:.5f}"), ("force_commanded_n", "map_force", "{:.5f}")])
    trace_csv.write(out_dir / "steering-governor.csv", r, SECONDS, columns=[
        ("time_s", "t", "{:.4f}"), ("speed_resting_mm_per_s", "free_speed", "{:.3f}"),
        ("force_resting_n", "free_force", "{:.5f}"), ("speed_governed_mm_per_s", "gov_speed", "{:.3f}"),
        ("force_governed_n", "gov_force", "{:.5f}")])
    end = trace_csv.end_sample(SECONDS, SR)
    ran = slice(0, end)

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw=dict(width_ratios=[1.4, 1]))
    h, w = DATA.shape
    ax[0].imshow(DATA, extent=(0, w * CELL_MM, h * CELL_MM, 0), cmap="Greys", alpha=0.6)
    ax[0].plot(r["x"][ran], r["y"][ran], lw=0.8, color="C0", label="puck (FrictionMouseIn)")
    ax[0].set_xlabel("x (mm)")
    ax[0].set_ylabel("y (mm)")
    ax[0].set_title("data map (grey: value), the raster scan")
    ax[0].legend(loc="lower right", fontsize=8)
    ax[1].plot(t[ran], r["map_force"][ran], lw=0.8, label="friction (N), cell by cell")
    ax[1].plot(t[ran], LO_N + (MAP_HI_N - LO_N) * r["value"][ran], lw=0.6, alpha=0.8,
               label="value, linear (the sound's pitch), in N")
    ax[1].set_xlabel("time (s)")
    ax[1].set_ylabel("force (N)")
    ax[1].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "surfaces-data-map.png", dpi=100)
    plt.close(fig)

    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(9, 5.5))
    ax[0].plot(t[ran], r["free_speed"][ran], lw=0.8, label=f"resting force {LO_N} N")
    ax[0].plot(t[ran], r["gov_speed"][ran], lw=0.8, label=f"SpeedGovernor (target {TARGET:g} mm/s, gain {GAIN} N per mm/s)")
    ax[0].axhline(TARGET, color="0.5", lw=0.6, ls="--")
    ax[0].set_ylabel("speed (mm/s)")
    ax[0].legend(fontsize=8)
    ax[1].plot(t[ran], r["free_force"][ran], lw=0.8)
    ax[1].plot(t[ran], r["gov_force"][ran], lw=0.8)
    ax[1].set_ylabel("force (N)")
    ax[1].set_xlabel("time (s)")
    fig.suptitle(f"friction that steers: a hand pushing with {PUSH_N} N")
    fig.tight_layout()
    fig.savefig(out_dir / "steering-governor.png", dpi=100)
    plt.close(fig)

    late = slice(int(0.5 * SR), end)
    free, gov = r["free_speed"][late], r["gov_speed"][late]
    settled = TARGET + (PUSH_N - LO_N) / GAIN
    return ["\n## 2D surfaces (issue 27, item 3) and a data map explored with sound and friction (item 5)\n",
            f"A 6 x 4 table of example values laid out {CELL_MM:g} mm a cell, scanned by "
            f"`FrictionHand.raster(48, 24, 4, 40, 0, 4)` (rows through the cells' centres at 40 mm/s; a firm hand, "
            f"`{FIRM_HAND}`). "
            "`SpatialBufRd2D` reads it at the puck's (x, y): linearly for the sound's value, cell by cell for the "
            f"friction ({LO_N} .. {MAP_HI_N} N). The puck covered x {r['x'][ran].min():.1f} .. "
            f"{r['x'][ran].max():.1f} mm, y {r['y'][ran].min():.1f} .. {r['y'][ran].max():.1f} mm; friction "
            f"{r['map_force'][ran].min():.3f} .. {r['map_force'][ran].max():.3f} N. "
            "Files: `surfaces-data-map.png` (the path over the map, force against time), `.csv`.\n",
            "\n## Friction that steers (issue 27, item 4)\n",
            f"`SpeedGovernor` (target {TARGET:g} mm/s, gain {GAIN} N per mm/s) against a simulated hand pushing "
            f"with {PUSH_N} N (`FrictionHand.force`), beside the resting force alone; speeds from FrictionMouseIn "
            "from 0.5 s to the end.\n",
            "| friction | mean speed (mm/s) | standard deviation (mm/s) | mean force (N) |",
            "|---|---|---|---|",
            f"| resting {LO_N} N | {free.mean():.1f} (the sensor's limit) | {free.std():.1f} | "
            f"{r['free_force'][late].mean():.3f} |",
            f"| SpeedGovernor | {gov.mean():.1f} (expected {settled:.1f}: target + (push - loForce) / gain) | "
            f"{gov.std():.1f} | {r['gov_force'][late].mean():.3f} |",
            "\nFiles: `steering-governor.png` (speed and force against time), `.csv`.\n"]


if __name__ == "__main__":
    import sys
    from pathlib import Path
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/gallery")
    out.mkdir(parents=True, exist_ok=True)
    print("\n".join(render(out)))
