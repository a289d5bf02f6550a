"""The trace CSV writer the pilot (scripts/main.sh) shares with other rendered scenes: no row after
the scene's synth was freed. The pilot's CSVs used to end with such a row (position 0 mm, force 0 N,
below the device's minimum force): scsynth -N renders to the end of the block after the Score's
last bundle, and those samples are zeros."""
import csv

import numpy as np

from kfharness import pilot as P
from kfharness import trace_csv


def test_the_trace_csv_ends_with_the_scene_not_with_the_render(tmp_path):
    # A short friction-on pilot scene ending mid-block, as the pilot's scenes do (10.222 s).
    scene = P.Scene("mapping1", 1, [[0.0, 0.0], [0.3, 20.0]], 5.0, 6.0, duration_s=0.3505)
    r = P.render(scene)
    end = trace_csv.end_sample(scene.duration_s, r["sr"])
    # The render itself has the artefact: all zero after the synth is freed.
    assert len(r["t"]) > end and not r["commanded_force"][end:].any() and not r["position"][end:].any()

    path = tmp_path / "trace.csv"
    rows_written = trace_csv.write(path, r, scene.duration_s)
    rows = list(csv.reader(path.open()))
    assert rows[0] == [name for name, _, _ in trace_csv.PILOT_COLUMNS]
    table = np.array(rows[1:], dtype=float)
    assert len(table) == rows_written == -(-end // 48)  # every 1 ms (48 samples) before the end
    assert table[-1, 0] < scene.duration_s
    # Friction on: every row's commanded force is at least the device's minimum (the magnet off),
    # the last row included, and the last position is where the puck stopped (> 0 mm).
    assert table[:, 6].min() >= P.MIN_FORCE_N
    last = (len(table) - 1) * 48
    assert table[-1, 1] == float(f"{r['position'][last]:.4f}") and table[-1, 1] > 1.0
