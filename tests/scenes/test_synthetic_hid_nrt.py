"""The synthetic hid-recorder recordings (tests/data/hid, made by make_synthetic.py there from
one known movement) replayed through FrictionMouseIn in a Score: the 125 Hz 8-bit mouse's
saturated reports are posted at open and its puck ends short of the movement by what they lost;
the 8 kHz 16-bit mouse follows the movement to its count."""
import numpy as np

from kfharness import nrt, paths

SR = 48000
HID_DIR = paths.test_data_dir() / "hid"
SLOW = HID_DIR / "synthetic-125hz-8bit-boot.hid"
FAST = HID_DIR / "synthetic-8khz-16bit-gaming.hid"
SLOW_COUNT_MM, FAST_COUNT_MM = 0.021, 25.4 / 3200  # 1210 and 3200 CPI (the README's table)
FAST_T_S = 1 / 8000


def boot_deltas():
    """(dx, dy) of each report of the 125 Hz file, decoded here by hand: buttons, X, Y, wheel
    bytes, X and Y signed."""
    rows = []
    for line in SLOW.read_text().splitlines():
        if line.startswith("E:"):
            report = bytes(int(h, 16) for h in line.split()[3:])
            rows.append(tuple(int.from_bytes(report[i:i + 1], "little", signed=True) for i in (1, 2)))
    return np.array(rows)


def truth():
    """t, x, y of synthetic-trajectory.csv."""
    return np.loadtxt(HID_DIR / "synthetic-trajectory.csv", delimiter=",", comments="#")[:, :3]


def test_synthetic_recordings_through_the_ugens_saturation_posted():
    seconds = 1.4
    data, log = nrt.score_and_render("synthhid", f"""
        var slow = FrictionDevice.describeReplay("{SLOW}", 0, (countMm: {SLOW_COUNT_MM}));
        var fast = FrictionDevice.describeReplay("{FAST}", 1, (countMm: {FAST_COUNT_MM}));
        var def = SynthDef(\\synthhid, {{
            Out.ar(0, FrictionMouseIn.ar(0, 0, 1)[0..1] ++ FrictionMouseIn.ar(1, 0, 1)[0..1])
        }});
        score = Score([
            [0.0, slow.openMsg],
            [0.0, fast.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\synthhid, nil, 1000).newMsg],
            [{seconds}, slow.closeMsg],
            [{seconds}, fast.closeMsg],
            [{seconds} + 0.05, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=4)
    deltas = boot_deltas()
    saturated = int(np.sum(np.max(np.abs(deltas), axis=1) == 127))
    assert saturated > 0
    assert f"warning: {saturated} of {len(deltas)} reports at their field's limit" in log, log
    assert log.count("reports at their field's limit") == 1, "the 8 kHz file has none"

    t, x, y = truth().T
    end = int((seconds - 0.1) * SR)  # still since 1.2 s
    # 125 Hz: the puck ends where the reports' counts say, short of the movement by what the
    # saturated reports lost (more than a millimetre); Y never saturates.
    slow_x, slow_y = data[end, 0], data[end, 1]
    assert abs(slow_x - deltas[:, 0].sum() * SLOW_COUNT_MM) < 1e-4
    assert x[-1] - slow_x > 1.0
    assert abs(slow_y - y[-1]) <= SLOW_COUNT_MM / 2 + 1e-4
    # 8 kHz: to the sensor's half count at the end; during the movement within what one report
    # interval and one audio sample of lag at its fastest (537 mm/s) add to the half count.
    assert abs(data[end, 2] - x[-1]) <= FAST_COUNT_MM / 2 + 1e-4
    assert abs(data[end, 3] - y[-1]) <= FAST_COUNT_MM / 2 + 1e-4
    n = int(seconds * SR) - 64
    times = np.arange(n) / SR
    error = np.abs(data[:n, 2] - np.interp(times, t, x))
    assert error.max() <= 537 * (FAST_T_S + 1 / SR) + FAST_COUNT_MM / 2, error.max()
