"""FrictionMouseIn reconstructs a mouse at the rate it reports, measured from its reports, not
at the 125 Hz the device spec assumes: the Genius mouse of the test data reports at 500 Hz, so
its speed output after a report of dx counts is dx x 0.021 mm / 2 ms (not / 8 ms)."""
import struct

import numpy as np

from kfharness import nrt, paths

SR = 48000
COUNT_MM = 0.021
HID_FILE = paths.test_data_dir() / "hid" / "genius-gila-gaming-mouse-0458-0138.hid"


def hid_reports():
    """(time s, dx counts) of every report of the file, decoded here by hand."""
    rows = []
    for line in HID_FILE.read_text().splitlines():
        if line.startswith("E:"):
            fields = line.split()
            report = bytes(int(h, 16) for h in fields[3:])
            rows.append((float(fields[1]), struct.unpack("<h", report[2:4])[0]))
    return rows


def test_replayed_500_hz_mouse_is_reconstructed_at_500_hz():
    data, _ = nrt.score_and_render("rate500", """
        var dev = FrictionDevice.describeReplay("%s");
        var def = SynthDef(\\rate500, { Out.ar(0, FrictionMouseIn.ar(0, 0, 1)) });
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\rate500, nil, 1000).newMsg],
            [8.0, dev.closeMsg],
            [8.05, ['/c_set', 0, 0]]]);
    """ % HID_FILE, sample_rate=SR, channels=4)
    reports = hid_reports()
    speed = data[:, 2].astype(np.float64)
    checked = 0
    for i in range(len(reports) - 1):
        t, dx = reports[i]
        # From 3.5 s on the mouse moves steadily: most intervals are single polls (before, a
        # slow hand skips most polls and the lower quartile of intervals is 4 ms).
        if t < 3.5 or reports[i + 1][0] - t < 0.0015 or dx == 0:
            continue
        # The replay's time 0 is the Score's first block; a report is taken at the first sample
        # at or after its time, so look 0.5 ms after it.
        k = int(np.ceil((t + 0.0005) * SR))
        assert speed[k] == np.float32(dx * COUNT_MM / 0.002), (i, t, dx, speed[k])
        checked += 1
    assert checked > 200
    x = data[:, 0].astype(np.float64)
    assert abs(x[int(7.9 * SR)] - (-67 * COUNT_MM)) < 1e-4  # and it ends on the recording's sum
