"""FrictionDevice.mouse without a mouse: its OSC messages, mouse profiles written by sclang and
read by the server's reader, the stroke helper, clear errors, and a Score that tries to open a
real mouse (refused: a mouse is realtime only, never a silent simulator)."""
import re

import numpy as np

from kfharness import nrt, paths, sclang_session


def test_mouse_messages_and_specs():
    out = sclang_session.run(r"""
        var d = FrictionDevice.describeMouse(2, "0458:0138", \evdev, (countMm: 0.02), true);
        "KF-MSG %".format(d.openMsg).postln;
        "KF-MOUSEMSG %".format(d.mouseMsg == d.openMsg).postln;
        "KF-REPLACE %".format(FrictionDevice.describeMouse(1, replace: true).openMsg).postln;
        "KF-SPEC % %".format(d.specs[\countMm], d.specs[\maxSpeed]).postln;
        "KF-FIRST %".format(FrictionDevice.describeMouse(0).openMsg).postln;
        "KF-INDEX %".format(FrictionDevice.describeMouse(1, 3).openMsg).postln;
        "KF-REOPEN %".format(d.reopenMsg).postln;
        "KF-LIST %".format(FrictionDevice.listMiceMsg(\hidapi, "/tmp/x")).postln;
        "KF-RECORD %".format(d.recordMsg("/tmp/m.txt")).postln;
    """)
    assert "KF-MSG [ /cmd, kfOpenMouse, 2, 0458:0138, evdev, , grab, 1, countMm, 0.02 ]" in out
    assert "KF-MOUSEMSG true" in out
    assert "KF-REPLACE [ /cmd, kfOpenMouse, 1, , evdev, , replace, 1 ]" in out
    assert "KF-SPEC 0.02 317.5" in out  # 0.02 mm x 127 counts x 125 Hz
    assert "KF-FIRST [ /cmd, kfOpenMouse, 0, , evdev,  ]" in out  # Linux: evdev unless asked
    assert "KF-INDEX [ /cmd, kfOpenMouse, 1, 3, evdev,  ]" in out
    assert "KF-REOPEN [ /cmd, kfReopenMouse, 2 ]" in out
    assert "KF-LIST [ /cmd, kfListMice, hidapi, /tmp/x ]" in out
    assert "KF-RECORD [ /cmd, kfRecord, 2, /tmp/m.txt ]" in out


def test_stroke_and_profile_round_trip():
    path = paths.work_dir() / "gila-profile.txt"
    out = sclang_session.run(f"""
        var x = FrictionDevice.countMmFromStroke(-4731, 100), y = FrictionDevice.countMmFromStroke(4690, 100);
        var p, d;
        FrictionDevice.writeMouseProfile("{path}", (name: "Genius Gila", vendorId: "0458", productId: "0138",
            cpi: 1200, countMmX: x, countMmY: y, updateRateHz: 500));
        p = FrictionDevice.readMouseProfile("{path}");
        "KF-P % % % %".format(p[\\name], p[\\vendorId], (p[\\countMmX] - x).abs < 1e-9, p[\\cpi]).postln;
        d = FrictionDevice.describeMouse(0, nil, \\hidapi, "{path}");
        "KF-D % % %".format(d.specs[\\countMm].round(1e-7), d.specs[\\updateRate], d.openMsg).postln;
        "KF-CPI %".format(FrictionDevice.mouseProfileSettings((cpi: 1000))[\\countMm]).postln;
    """)
    assert re.search(r"KF-P Genius Gila 0458 true 1200(\.0)?$", out, re.M)
    assert re.search(r"KF-D 0\.0211372 500(\.0)? \[ /cmd, kfOpenMouse, 0, , hidapi, " + re.escape(str(path)) +
                     r", countMm, 0\.021137\d*, updateRateHz, 500(\.0)? \]", out), out[-1500:]
    assert "KF-CPI 0.0254" in out
    text = path.read_text()
    assert text.startswith("# kf-mouse-profile 1\n")
    assert "countMmX = 0.021137" in text and "vendorId = 0458" in text


def test_bad_mouse_arguments_give_clear_errors():
    out = sclang_session.run(r"""
        [
            { FrictionDevice.describeMouse(0, nil, \usb) },
            { FrictionDevice.describeMouse(0, 3.5) },
            { FrictionDevice.describeMouse(0, nil, \hidapi, "/no/such/profile.txt") },
            { FrictionDevice.countMmFromStroke(0, 100) },
            { FrictionDevice.countMmFromStroke(100, -1) },
        ].do { |f, i| f.try { |e| "KF-ERR % %".format(i, e.errorString).postln } };
    """)
    errors = {int(m.group(1)): m.group(2) for m in re.finditer(r"^KF-ERR (\d) (.*)$", out, re.M)}
    assert "backend must be \\hidapi or \\evdev" in errors[0]
    assert "which must be nil, an index" in errors[1]
    assert "no such file: /no/such/profile.txt" in errors[2]
    assert "counted nothing" in errors[3]
    assert "strokeMm must be a positive length" in errors[4]


def test_a_score_cannot_open_a_real_mouse_and_nothing_moves():
    data, log = nrt.score_and_render("mouse_nrt", """
        var def = SynthDef(\\mouseNrt, { Out.ar(0, FrictionMouseIn.ar(0)) });
        score = Score([
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, FrictionDevice.describeMouse(0).openMsg],
            [0.0, Synth.basicNew(\\mouseNrt, nil, 1000).newMsg],
            [0.2, ['/c_set', 0, 0]]]);
    """, channels=4)
    assert "kfOpenMouse: a real mouse needs a realtime server" in log
    assert "FrictionMouseIn: no device is open at index 0" in log  # not a simulator in its place
    assert np.all(data == 0.0)
