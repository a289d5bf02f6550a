"""sclang as a user with hardware writes it, on a realtime server (JACK dummy) with the board
emulator: answers matched to their callers by (command, slot), not by the order they come;
FrictionDevice.hardware's one answer for the mouse, the board and the calibration, and the device
it opened closed again when a later part is refused; addBoard refused on a replay device; the
board methods waiting for their answers; the board opened again after a reboot.

No mouse here (CI has none): hardware() itself is run to its refusal of the mouse; its board
sequence (prInitBoard, then the open of FrictionDevice.hardware) is run on simulated devices,
whose open stands in for kfOpenMouse."""
import re

from kfharness import paths, sclang

HID = paths.test_data_dir() / "hid" / "genius-gila-gaming-mouse-0458-0138.hid"


def test_answers_by_slot_hardware_sequence_and_board_methods(jack):
    table = paths.work_dir() / "hardware-calibration.txt"
    run = sclang.require_ok(sclang.run_with_server(sclang.fill(r"""
        var a, b, got = (), order = List.new, cond = Condition.new, withBoard, e, dev, replay, t0, slot2S;
        var catch = { |name, f| try { f.value; ("KF-" ++ name ++ " ok" ++ "\n").post } { |err|
            ("KF-" ++ name ++ " ERROR " ++ (err.what ? err.errorString) ++ "\n").post } };
        // The raw answers, in the order they come.
        OSCFunc({ |m| order.add("done " ++ m[1]) }, '/done', s.addr);
        OSCFunc({ |m| order.add("kfDone % %".format(m[2], FrictionAnswers.textOf(m))) }, '/kfDone', s.addr);
        OSCFunc({ |m| order.add("fail " ++ m[2]) }, '/kfFail', s.addr);
        a = FrictionDevice.sim(s, 1);
        b = FrictionDevice.sim(s, 2);

        // 1. Two board opens in flight: slot 1's, sent first in a bundle for 1 s from now,
        // will fail; slot 2's, sent right after for now, succeeds and so answers first (as two
        // clients' commands, or a scheduled and an immediate one, can).
        [[1, a.addBoardMsg("KF-NO-SUCH-BOARD")], [2, b.addBoardMsg(emulate: true)]].do { |pair|
            FrictionAnswers.expect(s, \kfBoardOpen, pair[0], {
                got[pair[0]] = "done"; slot2S = Main.elapsedTime - t0; cond.unhang
            }, { |reason|
                got[pair[0]] = "fail " ++ reason; cond.unhang
            });
        };
        // 1 s ahead: slot 2's whole emulated open (KF-SLOT2-S) must end before slot 1's stages
        // start for the premise (slot 2 answers first) to hold; see the assertion below.
        t0 = Main.elapsedTime;
        s.sendBundle(1.0, a.addBoardMsg("KF-NO-SUCH-BOARD"));
        s.sendBundle(nil, b.addBoardMsg(emulate: true));
        while { got.size < 2 } { cond.hang };
        ("KF-SLOT1 " ++ got[1] ++ "\n").post;
        ("KF-SLOT2 " ++ got[2] ++ "\n").post;
        ("KF-SLOT2-S " ++ slot2S ++ "\n").post;
        ("KF-ORDER " ++ order.reject { |o| o.contains("kfOpenSim") }.join(", ") ++ "\n").post;

        // 2. hardware(): the mouse refused (none here); nothing else is sent, one Error.
        catch.("HW-MOUSE", { FrictionDevice.hardware(s, "/dev/hidraw-kf-none", \emulate, index: 3) });
        ("KF-HW-MOUSE-HELD " ++ FrictionDevice.at(s, 3) ++ "\n").post;
        catch.("HW-BADBOARD", { FrictionDevice.hardware(s, nil, 42) });

        // 3. Its board sequence on a simulated device: all parts succeed, one answer.
        withBoard = { |index, board, calibration|
            FrictionDevice.new.prInit(s, index, \sim).prInitBoard(board, calibration, "test").prOpen
        };
        FrictionCalibration([[0, 0.14], [0.25, 0.77], [1, 1.4]], "KF-EMU-0001").write(@table@);
        catch.("SEQ-OK", { dev = withBoard.(5, \emulate, @table@) });
        ("KF-SEQ-OK-STATE " ++ [dev.state, FrictionDevice.at(s, 5) === dev, dev.boardSetup[\emulate]] ++ "\n").post;
        // 4. The board refused: the device it opened is closed again; so is it when the
        // calibration is refused. The slot is free at once for the next open.
        catch.("SEQ-BOARD", { c = withBoard.(6, "KF-NO-SUCH-BOARD") });
        catch.("SEQ-CAL", { withBoard.(7, \emulate, "/nonexistent/kf-calibration.txt") });
        ("KF-SEQ-HELD " ++ [FrictionDevice.at(s, 6), FrictionDevice.at(s, 7)] ++ "\n").post;
        catch.("SEQ-FREE", { FrictionDevice.sim(s, 6).close; FrictionDevice.sim(s, 7).close });
        // Outside a Routine: one ERROR posted for the whole.
        AppClock.sched(0, { withBoard.(8, "KF-NO-SUCH-BOARD"); nil });
        0.5.wait;
        s.sync;

        // 5. addBoard on a replay device: refused in sclang, and by the server when sent raw.
        replay = FrictionDevice.replay(s, @hid@, 4);
        catch.("REPLAY-SCLANG", { replay.addBoard(emulate: true) });
        catch.("REPLAY-SERVER", { FrictionAnswers.send(s, \kfBoardOpen, 4, ['/cmd', \kfBoardOpen, 4, "", 1, 2]) });

        // 6. The board methods wait for their answers: arm, then the status shows it armed.
        dev.arm;
        e = dev.boardStatus;
        ("KF-ARMED " ++ [e[\hasBoard], e[\armed], e[\boardState]] ++ "\n").post;
        dev.disarm;
        e = dev.boardStatus({ |v| ("KF-ACTION " ++ v[\armed] ++ "\n").post });
        ("KF-DISARMED " ++ e[\armed] ++ "\n").post;
        e = a.boardStatus;  // a device without a board
        ("KF-NO-BOARD " ++ [e[\hasBoard], e[\armed]] ++ "\n").post;
        catch.("STATUS-EMPTY", { FrictionDevice.new.prInit(s, 9, \sim).boardStatus });
        catch.("ARM-NO-BOARD", { a.arm });
        // Posted when it comes: the status asked for after it is answered after it (the server
        // answers in order), so once that one is back, this one has been posted.
        AppClock.sched(0, { dev.boardStatus; cond.unhang; nil });
        cond.hang;
        dev.boardStatus;

        // 7. A reboot opens the device again with its board and calibration (disarmed).
        s.quit;
        // Until the process has exited: SC 3.13's boot waits 1 s for it (Server:prWaitForPidRelease)
        // and then boots nothing, silently (a sanitized server's exit took longer beside a second
        // test command).
        while { s.serverRunning or: { s.pid.notNil } } { 0.05.wait };
        s.bootSync;
        while { dev.state == \opening } { 0.05.wait };
        e = dev.boardStatus;
        ("KF-REBOOT " ++ [dev.state, e[\hasBoard], e[\armed]] ++ "\n").post;
        [a, b, dev, replay].do(_.close);
        s.sync;
    """, table=sclang.sc_string(table), hid=sclang.sc_string(HID)), jack, name="hardware"))
    out = run.output

    def line(tag):
        found = [l[len(tag) + 1:] for l in out.splitlines() if l.startswith(tag + " ")]
        assert len(found) == 1, (tag, found, out[-4000:])
        return found[0]

    # 1. Each caller got its own answer although slot 2's came first (matching by name and order
    # gave slot 1 the success and left slot 2 to time out).
    assert line("KF-SLOT1").startswith("fail kfBoardOpen: "), out[-4000:]
    assert line("KF-SLOT2") == "done"
    # The premise's margin: slot 2's open answered within the 1 s before slot 1's is due.
    print("slot 2's emulated board open answered in", line("KF-SLOT2-S"), "s")
    assert float(line("KF-SLOT2-S")) < 1.0, "slot 2's open took longer than slot 1's lead"
    assert line("KF-ORDER") == "done kfBoardOpen, kfDone 2 kfBoardOpen, fail 1", "the premise: the failure answers last"
    # 2. hardware(): the mouse's refusal, nothing held, no board opened for it.
    assert line("KF-HW-MOUSE").startswith("ERROR FrictionDevice kfOpenMouse: /dev/hidraw-kf-none")
    assert "closed again" not in line("KF-HW-MOUSE")
    assert line("KF-HW-MOUSE-HELD") == "nil"
    assert not re.search(r"^kfBoardOpen 3 ", out, re.M)
    assert "board must be nil (the first board), a serial String or \\emulate, got 42" in line("KF-HW-BADBOARD")
    # 3. The sequence: open, board, calibration, one answer, the device held with its board.
    assert line("KF-SEQ-OK") == "ok"
    assert line("KF-SEQ-OK-STATE") == "[ open, true, true ]"
    assert re.search(r"^kfBoardOpen 5 board KF-EMU-0001 \(emulated\)", out, re.M)
    # 4. A refused part: one Error naming it and the undone open; the slots free again.
    board = line("KF-SEQ-BOARD")
    assert board.startswith("ERROR FrictionDevice kfBoardOpen: ") and board.endswith(
        "; the sim device it opened in slot 6 was closed again"), board
    cal = line("KF-SEQ-CAL")
    assert cal.startswith("ERROR FrictionDevice kfBoardCalibrate: ") and cal.endswith(
        "; the sim device it opened in slot 7 was closed again"), cal
    assert line("KF-SEQ-HELD") == "[ nil, nil ]"
    assert line("KF-SEQ-FREE") == "ok"
    outside = [l for l in out.splitlines() if l.startswith("ERROR: FrictionDevice kfBoardOpen: ")]
    assert len(outside) == 1 and outside[0].endswith("slot 8 was closed again"), outside
    # 5. A replay device cannot carry a board: sclang says why; the server says the same.
    assert "replays a recording, whose puck is not the one on the magnet" in line("KF-REPLAY-SCLANG")
    server = line("KF-REPLAY-SERVER")
    assert server.startswith("ERROR FrictionDevice kfBoardOpen: device 4 replays a recording, whose puck is not"), \
        server
    # 6. The board methods: answered in order inside a Routine; status waits and returns.
    assert line("KF-ARMED") == "[ true, true, armed ]"
    assert line("KF-ACTION") == "false" and line("KF-DISARMED") == "false"
    assert line("KF-NO-BOARD") == "[ false, false ]"
    assert line("KF-STATUS-EMPTY") == "ERROR FrictionDevice kfBoardStatus: no device is open at index 9"
    assert "has no board" in line("KF-ARM-NO-BOARD")
    assert re.search(r"^FrictionDevice\(sim, 5\) board status: \(", out, re.M), out[-3000:]
    # 7. Re-opened after the reboot with its board, calibrated again.
    assert line("KF-REBOOT") == "[ open, true, false ]"
    after = out.split("KF-ARM-NO-BOARD")[1]
    assert re.search(r"^kfBoardOpen 5 board KF-EMU-0001", after, re.M) and "kfBoardCalibrate" not in after
