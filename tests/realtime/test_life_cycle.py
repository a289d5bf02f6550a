"""The device life cycle on a realtime server (issue 14): answers and refusals, taken slots,
Cmd-., reboot and ProxySpace, as SuperCollider users expect them.

Each test prints its measured figures on a line starting with KF-FIGURE.
"""
import numpy as np

from kfharness import paths, readers, sclang


def values(run, tag):
    return [r for r in run.lines(tag)]


def test_a_rejected_open_is_an_error_and_a_taken_slot_is_refused_unless_replaced(jack):
    run = sclang.require_ok(sclang.run_with_server(r"""
        var bad, a, b, c, x = 0;
        // 1. The server rejects an unknown setting: an Error in sclang, with the server's reason.
        try { bad = FrictionDevice.sim(s, 0, profile: (noSuchSetting: 1)) } { |e|
            ("KF-REJECTED " ++ e.errorString).postln };
        "KF-ALL-AFTER-REJECT %".format(FrictionDevice.all.size).postln;
        // 2. A taken slot: refused in sclang ...
        a = FrictionDevice.sim(s, 0, FrictionHand.speeds([[40, 5]]));
        try { FrictionDevice.sim(s, 0) } { |e| ("KF-TAKEN " ++ e.errorString).postln };
        // ... and by the server, for any client that sends the open itself.
        OSCdef(\kfFail, { |msg| ("KF-SERVER-FAIL " ++ msg[3..].collect { |c| c.asInteger.asAscii }.join).postln },
            '/kfFail');
        s.sendMsg(*FrictionDevice.sim(nil, 0).openMsg);
        s.sync;
        0.2.wait;
        "KF-A-OPEN % %".format(a.isOpen, FrictionDevice.at(s, 0) === a).postln;
        // 3. Replaced explicitly: the old object no longer closes the slot.
        b = FrictionDevice.sim(s, 0, FrictionHand.speeds([[40, 5]]), replace: true);
        "KF-REPLACED % % %".format(a.isOpen, b.isOpen, FrictionDevice.at(s, 0) === b).postln;
        a.close;
        s.sync;
        OSCdef(\kfX, { |msg| x = msg[3] }, '/kfX');
        c = { SendReply.kr(Impulse.kr(20), '/kfX', FrictionMouseIn.kr(0)[0]); Silent.ar }.play;
        0.6.wait;
        "KF-STILL-OPEN % %".format(b.isOpen, x).postln;
        b.close;
        s.sync;
        "KF-CLOSED % %".format(b.isOpen, FrictionDevice.all.size).postln;
        c.free;
        // 4. s.sync after every command, and a command on a closed slot fails with its reason.
        try { b.zero } { |e| ("KF-ZERO-CLOSED " ++ e.errorString).postln };
        s.sync;
        "KF-SYNCED".postln;
    """, jack, name="answers"))
    rejected = run.lines("KF-REJECTED ")
    assert rejected and "unknown setting" in " ".join(rejected[0]) and "noSuchSetting" in " ".join(rejected[0])
    assert " ".join(rejected[0]).count("kfOpenSim") == 1, f"the command is named once: {rejected[0]}"
    assert values(run, "KF-ALL-AFTER-REJECT ") == [["0"]]
    assert "is taken" in " ".join(run.lines("KF-TAKEN ")[0])
    assert "taken" in " ".join(run.lines("KF-SERVER-FAIL ")[0])
    assert values(run, "KF-A-OPEN ") == [["true", "true"]]
    assert values(run, "KF-REPLACED ") == [["false", "true", "true"]]
    still = run.lines("KF-STILL-OPEN ")[0]
    assert still[0] == "true" and float(still[1]) > 5, "closing the replaced object closed the new device"
    assert values(run, "KF-CLOSED ") == [["false", "0"]]
    assert "no device is open" in " ".join(run.lines("KF-ZERO-CLOSED ")[0])
    assert run.lines("KF-SYNCED")


def test_pilot_and_force_writer_recover_from_cmd_period(jack):
    record = paths.work_dir() / "cmdperiod.kfs"
    record.unlink(missing_ok=True)
    run = sclang.require_ok(sclang.run_with_server(f"""
        var dev, pilot, src;
        ~fails = 0;
        OSCdef(\\kfFailWatch, {{ |msg| ~fails = ~fails + 1; msg.postln }}, '/fail');
        dev = FrictionDevice.sim(s, 0, FrictionHand.speeds([[20, 10]]));
        dev.forceBus;
        pilot = FrictionPilot(dev).play;
        s.sync; 0.5.wait;
        "KF-BEFORE %".format(pilot.isPlaying).postln;
        CmdPeriod.run;
        1.0.wait;
        "KF-AFTER-CMDPERIOD % %".format(pilot.isPlaying, dev.isOpen).postln;
        pilot.mapping_(\\mapping2);    // no synth: nothing sent, no 'Node not found'
        pilot.play;
        s.sync; 0.3.wait;
        pilot.mapping_(\\mapping3);
        s.sync;
        "KF-REPLAYED %".format(pilot.isPlaying).postln;
        pilot.free;
        // The device's force writer is back: a source into forceBus reaches the device.
        dev.record({sclang.sc_string(record)});
        src = {{ Out.ar(dev.forceBus, DC.ar(0.5)) }}.play;
        0.5.wait;
        src.free;
        dev.close;
        "KF-FAILS %".format(~fails).postln;
    """, jack, name="cmdperiod"))
    assert values(run, "KF-BEFORE ") == [["true"]]
    assert values(run, "KF-AFTER-CMDPERIOD ") == [["false", "true"]]
    assert values(run, "KF-REPLAYED ") == [["true"]]
    assert values(run, "KF-FAILS ") == [["0"]], run.output[-3000:]
    assert "Node" not in run.output.split("KF-BEFORE")[1] or "not found" not in run.output.split("KF-BEFORE")[1]
    _, records = readers.read_session(record)
    commanded = np.array([f[3] for tag, f in records if tag == "F"])
    print(f"KF-FIGURE force_frames_after_cmd_period_at_0.5N {int(np.sum(np.isclose(commanded, 0.5, atol=1e-4)))}")
    assert np.sum(np.isclose(commanded, 0.5, atol=1e-4)) > 200


def test_devices_are_opened_again_after_a_reboot(jack):
    run = sclang.require_ok(sclang.run_with_server(r"""
        var dev, c, x = 0, cond = Condition(false);
        dev = FrictionDevice.sim(s, 1, FrictionHand.speeds([[30, 20]]));
        1.0.wait;
        s.quit;
        2.0.wait;
        "KF-DURING-QUIT %".format(dev.isOpen).postln;
        s.bootSync;
        1.0.wait;
        "KF-AFTER-REBOOT % %".format(dev.isOpen, FrictionDevice.at(s, 1) === dev).postln;
        OSCdef(\kfX, { |msg| x = msg[3] }, '/kfX');
        c = { SendReply.kr(Impulse.kr(20), '/kfX', FrictionMouseIn.kr(1)[0]); Silent.ar }.play;
        1.0.wait;
        "KF-MOVING %".format(x).postln;
        c.free;
        dev.close;
    """, jack, name="reboot", timeout=180))
    assert values(run, "KF-DURING-QUIT ") == [["false"]]
    assert values(run, "KF-AFTER-REBOOT ") == [["true", "true"]]
    x = float(run.lines("KF-MOVING ")[0][0])
    print(f"KF-FIGURE x_mm_one_second_after_reboot {x}")
    assert x > 10, "the re-opened simulation moves the puck again"
    assert "no device is open" not in run.output.split("KF-AFTER-REBOOT")[1]


def test_a_device_in_a_proxyspace_plays_the_puck_position(jack):
    run = sclang.require_ok(sclang.run_with_server(r"""
        var p = ProxySpace.push(s), vals;
        ~dev = FrictionDevice.sim(s, 2, FrictionHand.speeds([[30, 5]]));
        1.5.wait;
        "KF-PROXY % % %".format(~dev.source.class, ~dev.source.isOpen, ~dev.numChannels).postln;
        ~dev.bus.getn(4, { |v| vals = v });
        s.sync; 0.1.wait;
        "KF-PROXY-X %".format(vals[0]).postln;
        ~dev.source.close;
        p.pop;
    """, jack, name="proxyspace"))
    assert values(run, "KF-PROXY ") == [["FrictionDevice", "true", "4"]]
    assert float(run.lines("KF-PROXY-X ")[0][0]) > 10
