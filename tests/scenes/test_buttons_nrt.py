"""FrictionButtons: the puck's buttons, read from a replayed recording whose reports press them at
known times. A button reads 1 from the block of the first report holding it down to the block of
the report that releases it (held between reports); a click held for a single report still shows;
a slot with no device reads 0."""
import numpy as np

from kfharness import nrt, paths

RATE, BLOCK = 48000, 64
REPORT_S = 0.008
# (first report down, first report up) per button bit: left held 0.104..0.2 s, right for one
# report at 0.304 s, both at once from 0.4 s for two reports.
PRESSES = {1: [(0.104, 0.2), (0.4, 0.416)], 2: [(0.304, 0.312), (0.4, 0.416)]}


def _buttons_at(t):
    return sum(bit for bit, spans in PRESSES.items() if any(a - 1e-9 <= t < b - 1e-9 for a, b in spans))


def test_buttons_follow_the_reports():
    session = paths.work_dir() / "buttons.kfs"
    lines = ["kf-session 1 countMm=0.021 updateRateHz=125"]
    for i in range(1, 70):
        t = i * REPORT_S
        lines.append(f"R {t:.3f} {t:.3f} 1 0 {_buttons_at(t)} 0")
    session.write_text("\n".join(lines) + "\n")
    data, log = nrt.score_and_render("buttons", f"""
        var def = SynthDef(\\buttons, {{ Out.ar(0, FrictionButtons.ar(0) ++ [K2A.ar(FrictionButtons.kr(3)[0])]) }});
        score = Score([
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, ['/cmd', \\kfOpenReplay, 0, "{session}"]],
            [0.0, Synth.basicNew(\\buttons, nil, 1000).newMsg],
            [0.55, ['/c_set', 0, 0]]]);
    """, channels=4)
    assert "FrictionButtons: no device is open at index 3" in log
    assert np.all(data[:, 2] == 0) and np.all(data[:, 3] == 0), "middle button and slot 3: 0"
    for channel, bit in ((0, 1), (1, 2)):
        down = data[:, channel] > 0.5
        edges = np.flatnonzero(np.diff(down.astype(int))) + 1
        want = [round(t * RATE) for a, b in PRESSES[bit] for t in (a, b)]
        # Each edge is in the block whose span holds the report's time (a replay pumped to the end
        # of each block delivers the report there), so within one block of it.
        assert len(edges) == len(want), (bit, edges, want)
        assert np.all(np.abs(edges - np.array(want)) <= BLOCK), (bit, edges, want)
        assert set(np.unique(data[:, channel])) <= {0.0, 1.0}
