"""A realtime server asked for a real mouse on a machine that may have none (CI has none): the
server answers listMice, and opening fails with a message naming what is wrong; the slot stays
closed (FrictionMouseIn says so) - never a simulator in the mouse's place."""
from kfharness import sclang


def test_list_and_open_without_a_mouse(jack):
    run = sclang.require_ok(sclang.run_with_server(r"""
        var cond = Condition.new, found;
        FrictionDevice.listMice(s, nil, { |mice| found = mice; cond.unhang });
        cond.hang;
        "KF-MICE %\n".postf(found.size);
        found.do { |m| "KF-MOUSE % % %\n".postf(m[\backend], m[\index], m[\path]) };
        SynthDef(\kfMousePos, { SendReply.kr(Impulse.kr(20), '/kfMousePos', FrictionMouseIn.kr(0)) }).add;
        OSCdef(\kfMousePos, { |msg| "KF-POS %\n".postf(msg[3..6].join(" ")) }, '/kfMousePos');
        s.sync;
        // Inside a Routine an open the server refuses is an Error, with the server's reason.
        [
            { if(found.isEmpty) { FrictionDevice.mouse(s, 0) } },  // "the first mouse": there is none
            { FrictionDevice.mouse(s, 1, "/dev/hidraw-kf-none", \hidapi) },
            { FrictionDevice.mouse(s, 2, "/dev/input/event-kf-none", \evdev, nil, true) }
        ].do { |open| try(open) { |error| "KF-REFUSED %\n".postf(error.errorString) } };
        s.sendMsg('/cmd', 'kfReopenMouse', 3);
        s.sync;
        Synth(\kfMousePos);
        0.5.wait;
        "KF-NO-MOUSE %\n".postf(found.isEmpty);
    """, jack, name="mouse"))
    out = run.output
    count = int(run.lines("KF-MICE ")[0][0])
    assert "kfListMice: hidapi: " in out and "kfListMice: evdev: " in out
    assert len(run.lines("KF-MOUSE ")) == count
    if count == 0:
        assert "kfOpenMouse: no mouse found" in out
        assert "FrictionMouseIn: no device is open at index 0" in out
        rows = run.lines("KF-POS ")
        assert len(rows) >= 5 and all(float(v) == 0.0 for row in rows for v in row)
    assert len(run.lines("KF-REFUSED ")) == (3 if count == 0 else 2), out[-3000:]
    # A path is opened only if it is a mouse the backend lists (never a keyboard's node): say so.
    assert "kfOpenMouse: /dev/hidraw-kf-none is not a mouse this backend lists" in out
    assert "kfOpenMouse: /dev/input/event-kf-none is not a mouse this backend lists" in out
    assert "kfReopenMouse: no mouse is open at index 3" in out
