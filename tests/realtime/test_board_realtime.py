"""The friction board through the plugin on a realtime server (JACK dummy), with the board
emulator standing in for USB hardware: kfBoardOpen, kfBoardArm, kfBoardCalibrate, kfBoardClose,
and kfStatus's board lines, which report the emulated board's own status frames."""
import re

import pytest

from kfharness import paths, sclang

BOARD_LINE = re.compile(r"^kfStatus 5: board (\S+) (connected|NOT CONNECTED), (armed|disarmed), force at 1 kHz; "
                        r"board state (\w+), current ([0-9.]+) of full scale")
COUNTS_LINE = re.compile(r"^kfStatus 5: board set-points sent .*, resets (\d+)")
TIMING_LINE = re.compile(r"^kfStatus 5: frames per 1 ms pump 0/1/2/3\+: ([0-9.]+)/([0-9.]+)/([0-9.]+)/([0-9.]+)")


def test_emulated_board_follows_arming_calibration_and_the_watchdog(jack):
    table = paths.work_dir() / "board-calibration.txt"
    run = sclang.require_ok(sclang.run_with_server(f"""
        var dev, hold, phase = {{ |name|
            3.do {{ dev.status; s.sync; 0.05.wait }};
            0.05.wait;
            ("KF-PHASE " ++ name ++ "\n").post
        }};
        dev = FrictionDevice.sim(s, 5);
        s.sync;
        dev.addBoard(emulate: true);
        s.sync;
        phase.(\\opened);
        hold = {{ FrictionOut.ar(5, DC.ar(0.77)) * 0 }}.play;  // 0.77 N: drive 0.5, linear
        0.3.wait;
        phase.(\\disarmed);
        dev.arm;
        0.3.wait;
        phase.(\\armed);
        dev.boardStatus {{ |e|
            ("KF-BOARD-STATUS " ++ [e.hasBoard, e.connected, e.armed, e.boardState, e.currentLevel.round(0.001),
                                    e.setPointsSent > 100, e.forceRateHz.asInteger] ++ "\n").post
        }};
        0.2.wait;
        FrictionCalibration([[0, 0.14], [0.25, 0.77], [1, 1.4]], "KF-EMU-0001").write({sclang.sc_string(table)});
        dev.calibrate({sclang.sc_string(table)});
        0.3.wait;
        phase.(\\calibrated);
        hold.free;
        0.3.wait;
        phase.(\\freed);
        dev.removeBoard;
        s.sync;
        phase.(\\removed);
        FrictionDevice.describeSim(5).arm;  // described only: nothing sent
        s.sendMsg('/cmd', 'kfBoardArm', 6, 1);  // no device in slot 6
        s.sync;
        dev.close;
        s.sync;
    """, jack, name="board"))
    lines = run.output.splitlines()
    # The paper's device frames force at 1 kHz: a 2.1 board is sent one level a frame.
    opened = re.compile(r"^kfBoardOpen 5 board KF-EMU-0001 \(emulated\) \(protocol 2\.1, .*, force at 1 kHz\) "
                        r"is disarmed")
    assert any(opened.match(l) for l in lines), \
        run.output[-3000:]
    assert "kfBoardArm 5 board armed" in run.output
    assert any(l.startswith("kfBoardArm: no device is open at index 6") for l in lines)

    # The board lines of each phase (three status reads), in order.
    phases, boards = [], []
    for line in lines:
        m = BOARD_LINE.match(line)
        if m:
            boards.append(m)
        if line.startswith("KF-PHASE "):
            phases.append((line.split()[1], boards))
            boards = []
    got = dict(phases)
    assert list(got) == ["opened", "disarmed", "armed", "calibrated", "freed", "removed"], phases

    def currents(name):
        return [float(m.group(5)) for m in got[name]]

    assert got["opened"] and all(m.group(2) == "connected" and m.group(3) == "disarmed" for m in got["opened"])
    assert currents("disarmed") == [0.0] * 3, "a disarmed board is not driven"
    assert all(m.group(3) == "armed" and m.group(4) == "armed" for m in got["armed"])
    # Every read while armed carries the commanded drive: the device thread runs realtime, so no
    # stall reaches the 10 ms watchdog (a 0.0 here is the magnet dropping out on stage).
    assert currents("armed") == [pytest.approx(0.5, abs=0.001)] * 3  # linear: (0.77 - 0.14) / 1.26
    assert currents("calibrated") == [pytest.approx(0.25, abs=0.001)] * 3  # exact at a table point
    assert currents("freed") == [0.0] * 3, "synth freed: the last FrictionOut gone drove the board off"
    assert got["removed"] == [], "no board after removeBoard"
    # The same through the reply sclang gets (FrictionDevice.boardStatus).
    replies = [l for l in lines if l.startswith("KF-BOARD-STATUS ")]
    assert len(replies) == 1, run.output[-3000:]
    assert replies[0].startswith("KF-BOARD-STATUS [ true, true, true, armed, "), replies
    assert replies[0].endswith(", true, 1000 ]") and " 0.5," in replies[0], replies
    # The emulated board's power-on reset is reported once: acknowledged by the CLEAR_ERRORS of
    # the open, not counted again by the one before ARM, nor by any status frame after.
    resets = [int(COUNTS_LINE.match(l).group(1)) for l in lines if COUNTS_LINE.match(l)]
    assert resets and all(n == 1 for n in resets), resets
    timing = [TIMING_LINE.match(l) for l in lines if TIMING_LINE.match(l)]
    assert timing, "kfStatus reports the frames per pump"
    print("\n".join(l for l in lines if l.startswith("kfStatus 5:")))
