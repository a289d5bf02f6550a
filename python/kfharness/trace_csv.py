"""The CSV of a rendered trace, one row per millisecond: what the pilot writes and what any other
scene rendered on the simulated device (a gallery) writes with it.

Only the samples while the scene's synth ran are rows. scsynth -N renders past the Score's last
bundle to the end of that block, and the synth is freed at the end (FrictionPilot.score frees it at
`duration`): the samples after that are all zero (position 0 mm, force 0 N, below the device's
minimum force), an artefact of the render, not something the device did."""
import csv

from . import nrt

PILOT_COLUMNS = [  # (header, channel of the render, format)
    ("time_s", "t", "{:.4f}"),
    ("position_mm", "position", "{:.4f}"),
    ("speed_mm_per_s", "speed", "{:.3f}"),
    ("audio", "audio", "{:.5f}"),
    ("delayed_audio", "delayed_audio", "{:.5f}"),
    ("force_requested_n", "force", "{:.5f}"),
    ("force_commanded_n", "commanded_force", "{:.5f}"),
]


def end_sample(end_s, sample_rate):
    """The first sample without the scene's synth: the server frees it in the block where a bundle
    stamped end_s runs (kfharness.nrt.bundle_start_sample, which knows scsynth's and supernova's)."""
    return nrt.bundle_start_sample(end_s, sample_rate)


def write(path, r, end_s, columns=PILOT_COLUMNS, period_s=0.001):
    """Writes r (a dict of channel name -> array, with 't' and 'sr') every period_s, up to the
    scene's end end_s (s, when the Score freed its synth), not beyond. Returns the rows written."""
    sr = r["sr"]
    step = max(1, int(round(sr * period_s)))
    last = min(len(r["t"]), end_sample(end_s, sr))
    rows = 0
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([name for name, _, _ in columns])
        for i in range(0, last, step):
            w.writerow([fmt.format(r[channel][i]) for _, channel, fmt in columns])
            rows += 1
    return rows
