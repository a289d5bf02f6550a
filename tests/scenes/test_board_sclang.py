"""sclang side of the friction board: FrictionCalibration (validation, file round trip, the
inverse the server computes), FrictionDevice's board messages, and a Score's board refused (a
board runs in real time only)."""
from kfharness import nrt, paths, sclang_session


def test_calibration_tables_validate_round_trip_and_invert():
    path = paths.work_dir() / "sclang-calibration.txt"
    out = sclang_session.run(f"""
        var table = FrictionCalibration([[0, 0.14], [0.2, 0.14], [0.5, 0.6], [0.8, 1.3], [1, 1.3]], "KF-7");
        var back, errors = List.new;
        table.write("{path}");
        back = FrictionCalibration.read("{path}");
        "KF-POINTS %".format(back.points == table.points).postln;
        "KF-SERIAL %".format(back.serial).postln;
        "KF-DRIVES %".format([0.0, 0.14, 0.37, 0.6, 1.3, 5].collect {{ |f| back.driveFor(f).round(1e-9) }}).postln;
        "KF-FORCES %".format([0, 0.35, 0.65, 1].collect {{ |d| back.forceFor(d).round(1e-9) }}).postln;
        [
            {{ FrictionCalibration([]) }},
            {{ FrictionCalibration([[0, 0.5], [0.5, 0.4]]) }},
            {{ FrictionCalibration([[0.5, 0.5], [0.5, 0.6]]) }},
            {{ FrictionCalibration([[0, 0.5], [1.5, 0.6]]) }},
            {{ FrictionCalibration([[0, -1]]) }},
            {{ FrictionCalibration([[0, \\x]]) }},
            {{ FrictionCalibration.read("/nonexistent/kf.txt") }},
            {{ FrictionCalibration.drives(1) }},
            {{ FrictionCalibration([[0, 0.14], [1, 1.4]]).write("{path}.noserial") }},
            {{ FrictionCalibration([[0, 0.14]], "KF 7") }}
        ].do {{ |f| try {{ f.value; errors.add("none") }} {{ |e| errors.add(e.errorString) }} }};
        errors.do {{ |e| ("KF-ERROR " ++ e).postln }};
    """)
    assert "KF-POINTS true" in out
    assert "KF-SERIAL KF-7" in out
    # Flat bottom: least drive 0; table points exact; linear between; clamped above.
    assert "KF-DRIVES [ 0.0, 0.0, 0.35, 0.5, 0.8, 0.8 ]" in out
    assert "KF-FORCES [ 0.14, 0.37, 0.95, 1.3 ]" in out
    errors = [l for l in out.splitlines() if l.startswith("KF-ERROR ")]
    assert len(errors) == 10 and not any("none" == e.split(" ", 1)[1] for e in errors), errors
    assert "not monotone" in errors[1] and "does not ascend" in errors[2] and "not in 0..1" in errors[3]
    assert "no such file" in errors[6]
    # A table names its board: no file without a serial, and a serial is one word.
    assert "give the serial of the board" in errors[8] and "one word" in errors[9]


def test_board_messages_for_scores():
    out = sclang_session.run("""
        var dev = FrictionDevice.describeSim(3);
        var table = FrictionCalibration.linear(0.14, 1.4);
        var errors = List.new;
        [dev.addBoardMsg, dev.addBoardMsg("KF-0001", true, 3), dev.armMsg, dev.disarmMsg,
         dev.calibrateMsg(nil), dev.calibrateMsg("/tmp/a.txt"), dev.removeBoardMsg].do { |m| ("KF-MSG " ++ m).postln };
        [{ dev.addBoardMsg(42) }, { dev.addBoardMsg(nil, false, 9) }, { dev.calibrateMsg(table) },
         { dev.calibrateMsg(3) }].do { |f| try { f.value; errors.add("none") } { |e| errors.add(e.errorString) } };
        errors.do { |e| ("KF-ERROR " ++ e).postln };
        ("KF-SPECS " ++ [FrictionDevice.paperSpecs[\\watchdogS], FrictionDevice.paperSpecs[\\maxDriveLevel]]).postln;
    """)
    msgs = [l[len("KF-MSG "):] for l in out.splitlines() if l.startswith("KF-MSG ")]
    assert msgs == ["[ /cmd, kfBoardOpen, 3, , 0, 2 ]", "[ /cmd, kfBoardOpen, 3, KF-0001, 1, 3 ]",
                    "[ /cmd, kfBoardArm, 3, 1 ]", "[ /cmd, kfBoardArm, 3, 0 ]", "[ /cmd, kfBoardCalibrate, 3,  ]",
                    "[ /cmd, kfBoardCalibrate, 3, /tmp/a.txt ]", "[ /cmd, kfBoardClose, 3 ]"], msgs
    errors = [l for l in out.splitlines() if l.startswith("KF-ERROR ")]
    assert len(errors) == 4 and "none" not in [e.split(" ", 1)[1] for e in errors], errors
    assert "write the FrictionCalibration to a file first" in errors[2]
    assert "KF-SPECS [ 0.01, 1 ]" in out


def test_a_score_cannot_carry_a_board():
    _, log = nrt.score_and_render("board_nrt", """
        var dev = FrictionDevice.describeSim(0);
        score = Score([[0.0, dev.openMsg], [0.0, dev.addBoardMsg(emulate: true)], [0.01, dev.armMsg],
            [0.02, ['/c_set', 0, 0]]]);
    """)
    assert "kfBoardOpen: device 0 renders in lockstep (a Score or NRT server) and a board runs in real time" in log
    assert "kfBoardOpen 0 board" not in log  # never opened
    assert "kfBoardArm: device 0 has no board" in log
