"""The device life cycle on a realtime server (issue 14): answers and refusals, taken slots,
Cmd-., reboot and ProxySpace, as SuperCollider users expect them.

Each test prints its measured figures on a line starting with KF-FIGURE.
"""
import re

import numpy as np

from kfharness import paths, sclang
from kfstudy import readers


def values(run, tag):
    return [r for r in run.lines(tag)]


def test_a_rejected_open_is_an_error_and_a_taken_slot_is_refused_unless_replaced(jack):
    run = sclang.require_ok(sclang.run_with_server(r"""
        var bad, a, b, c, x = 0;
        // 1. The server rejects an unknown setting: an Error in sclang, with the server's reason.
        try { bad = FrictionDevice.sim(s, 0, profile: (noSuchSetting: 1)) } { |e|
            ("KF-REJECTED " ++ e.errorString ++ "\n").post };
        "KF-ALL-AFTER-REJECT %\n".postf(FrictionDevice.all.size);
        // A nil server is Server.default, as everywhere in SC.
        x = FrictionDevice.sim(nil, 5);
        "KF-NIL-SERVER % %\n".postf(x.server === Server.default, x.isOpen);
        x.close;
        x = 0;
        // 2. A taken slot: refused in sclang ...
        a = FrictionDevice.sim(s, 0, FrictionHand.speeds([[40, 5]]));
        try { FrictionDevice.sim(s, 0) } { |e| ("KF-TAKEN " ++ e.errorString ++ "\n").post };
        // ... and by the server, for any client that sends the open itself.
        OSCdef(\kfFail, { |msg| ("KF-SERVER-FAIL " ++ msg[3..].collect { |c| c.asInteger.asAscii }.join ++ "\n").post },
            '/kfFail');
        s.sendMsg(*FrictionDevice.describeSim(0).openMsg);
        s.sync;
        0.2.wait;
        "KF-A-OPEN % %\n".postf(a.isOpen, FrictionDevice.at(s, 0) === a);
        // 3. Replaced explicitly: the old object no longer closes the slot.
        b = FrictionDevice.sim(s, 0, FrictionHand.speeds([[40, 5]]), replace: true);
        "KF-REPLACED % % %\n".postf(a.isOpen, b.isOpen, FrictionDevice.at(s, 0) === b);
        a.close;
        s.sync;
        OSCdef(\kfX, { |msg| x = msg[3] }, '/kfX');
        c = { SendReply.kr(Impulse.kr(20), '/kfX', FrictionMouseIn.kr(0)[0]); Silent.ar }.play;
        0.6.wait;
        "KF-STILL-OPEN % %\n".postf(b.isOpen, x);
        b.close;
        s.sync;
        "KF-CLOSED % %\n".postf(b.isOpen, FrictionDevice.all.size);
        c.free;
        // 4. s.sync after every command, and a command on a closed slot fails with its reason.
        try { b.zero } { |e| ("KF-ZERO-CLOSED " ++ e.errorString ++ "\n").post };
        s.sync;
        "KF-SYNCED\n".post;
    """, jack, name="answers"))
    rejected = run.lines("KF-REJECTED ")
    assert rejected and "unknown setting" in " ".join(rejected[0]) and "noSuchSetting" in " ".join(rejected[0])
    assert " ".join(rejected[0]).count("kfOpenSim") == 1, f"the command is named once: {rejected[0]}"
    assert values(run, "KF-ALL-AFTER-REJECT ") == [["0"]]
    assert values(run, "KF-NIL-SERVER ") == [["true", "true"]]
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
        var dev, pilot, src, ended;
        ~fails = 0;
        OSCdef(\\kfFailWatch, {{ |msg| ~fails = ~fails + 1; msg.postln }}, '/fail');
        dev = FrictionDevice.sim(s, 0, FrictionHand.speeds([[20, 10]]));
        dev.forceBus;
        pilot = FrictionPilot(dev).play;
        s.sync; 0.5.wait;
        "KF-BEFORE %\n".postf(pilot.isPlaying);
        CmdPeriod.run;
        1.0.wait;
        "KF-AFTER-CMDPERIOD % %\n".postf(pilot.isPlaying, dev.isOpen);
        pilot.mapping_(\\mapping2);    // no synth: nothing sent, no 'Node not found'
        pilot.play;
        s.sync; 0.3.wait;
        pilot.mapping_(\\mapping3);
        s.sync;
        "KF-REPLAYED %\n".postf(pilot.isPlaying);
        pilot.free;
        // The device's force writer is back: a source into forceBus reaches the device.
        dev.record({sclang.sc_string(record)});
        s.sync;
        // Half a second of audio time, not of the wall clock: a fresh clone's run framed 190
        // frames at 0.5 N in 0.5 s of sclang's clock (the server's audio behind it).
        src = {{ Out.ar(dev.forceBus, DC.ar(0.5) * Line.ar(1, 1, 0.5, doneAction: 2)) }}.play;
        ended = Condition.new;
        src.onFree {{ ended.test = true; ended.signal }};
        ended.wait;
        dev.close;
        "KF-FAILS %\n".postf(~fails);
    """, jack, name="cmdperiod"))
    assert values(run, "KF-BEFORE ") == [["true"]]
    assert values(run, "KF-AFTER-CMDPERIOD ") == [["false", "true"]]
    assert values(run, "KF-REPLAYED ") == [["true"]]
    assert values(run, "KF-FAILS ") == [["0"]], run.output[-3000:]
    assert "Node" not in run.output.split("KF-BEFORE")[1] or "not found" not in run.output.split("KF-BEFORE")[1]
    _, records = readers.read_session(record)
    commanded = np.array([f[3] for tag, f in records if tag == "F"])
    print(f"KF-FIGURE force_frames_after_cmd_period_at_0.5N {int(np.sum(np.isclose(commanded, 0.5, atol=1e-4)))}")
    # 500 frames at 0.5 N were framed (one per ms of audio time); those the device skipped for a
    # newer one when its thread ran late are not recorded. Measured at 51ae098: 485 to 500 (three
    # runs without realtime beside two CPU hogs, two with). A writer that did not come back
    # frames none; the bound leaves room for a machine far busier than those.
    assert np.sum(np.isclose(commanded, 0.5, atol=1e-4)) > 200


# Everything a device and the classes around it can hold on the server, through s.reboot as a
# user evaluates it: the device's forceBus and positionBus and their bus synths, its audio drive
# (FrictionDevice.loadDrive: the calibration the server holds for FrictionDrive), a FrictionPilot
# (its synth, buffer and monitorBus) with a FrictionView of it, a FrictionViewMonitor reading the
# device's own buses, and a device whose re-open throws (made so by giving it a hand it cannot
# send). A user's ServerBoot function of this server allocates buses first (SC runs a server's
# own functions before those for all servers), so the device's buses get other numbers. After the
# boot: no error but that device's, the default group, every device open again with its buses
# working, read at their new numbers, and nothing allocated after the boot sharing a bus with them.
REBOOT = r"""
    var dev, bad, pilotDev, pilot, view, monitor, busesOf, fb, pb, before, x0, x1, force, strays, overlaps = 0;
    var nodeOne = false, waited = 0, userBoot, userBuses, numbersBefore, drivePath, driveBus, drive;
    bad = FrictionDevice.sim(s, 0, FrictionHand.speeds([[30, 20]]));
    dev = FrictionDevice.sim(s, 1, FrictionHand.speeds([[30, 20]]));
    pilotDev = FrictionDevice.sim(s, 2, FrictionHand.speeds([[20, 20]]));
    fb = dev.forceBus;
    // An audio drive: the guide's circuit (10 V full scale, 0.5 A/V) and magnet table.
    FrictionCalibration([[0, 0.14], [0.25, 0.77], [1, 1.4]], "magnet-1").write(@DIR@ +/+ "kf-lc-magnet.txt");
    drivePath = @DIR@ +/+ "kf-lc-drive.txt";
    File.use(drivePath, "w", { |f|
        f.write("kf-drive 1\nmagnetTable kf-lc-magnet.txt\nfullScaleCurrentA 2\ntransconductanceAPerV 0.5\n"
            "outputFullScaleV 10\noutputSign 1\nmaxSafeCurrentA 2\ncurrentSourceLatencyS 0.00002\nmagnetLagS 0.0004\n")
    });
    dev.loadDrive(drivePath);
    pb = dev.positionBus;
    bad.forceBus;
    pilot = FrictionPilot(pilotDev, \mapping2, amp: 0).play;
    view = FrictionView.pilot(pilot);
    monitor = FrictionViewMonitor(dev, dev.forceBus, dev.positionBus);
    s.sync;
    1.0.wait;
    "KF-BEFORE % % % %\n".postf(dev.isOpen, pilot.isPlaying, view.monitor.running, monitor.frameCount > 0);
    bad.instVarPut(\source, \notAHand);
    numbersBefore = [fb.index, pb.index, pilot.monitorBus.index];
    userBoot = { userBuses = [Bus.audio(s, 2), Bus.control(s, 3)] };
    ServerBoot.add(userBoot, s);
    "KF-REBOOTING\n".post;
    s.reboot;
    // As a person waits for the boot to finish (ServerTree included).
    while { s.serverRunning.not and: { waited < 30 } } { 0.1.wait; waited = waited + 0.1 };
    s.sync;
    1.0.wait;
    OSCFunc({ nodeOne = true }, '/n_info', s.addr, argTemplate: [1]).oneShot;
    s.sendMsg('/n_query', 1);
    s.sync;
    0.2.wait;
    "KF-AFTER-REBOOT % % % % %\n".postf(nodeOne, dev.isOpen, FrictionDevice.at(s, 1) === dev, pilotDev.isOpen,
        bad.isOpen);
    ServerBoot.remove(userBoot, s);
    "KF-SAME-BUSES % %\n".postf(dev.forceBus === fb, dev.positionBus === pb);
    // Buses allocated after the boot, as a user's code would: none shares a channel with the
    // device's or the pilot's.
    strays = userBuses ++ [Bus.audio(s, 1), Bus.control(s, 4), Bus.control(s, 5), Bus.audio(s, 2), Bus.control(s, 1)];
    pilot.play;
    s.sync;
    "KF-NUMBERS % %\n".postf(numbersBefore, [fb.index, pb.index, pilot.monitorBus.index]);
    busesOf = [dev.forceBus, dev.positionBus, pilot.monitorBus];
    busesOf.do { |a|
        strays.do { |b|
            if(a.rate == b.rate and: { a.index < (b.index + b.numChannels) } and: { b.index < (a.index + a.numChannels) }) {
                "KF-SHARED % %\n".postf(a, b);
                overlaps = overlaps + 1;
            }
        }
    };
    "KF-OVERLAPS %\n".postf(overlaps);
    // The position reader writes positionBus, the force writer sends forceBus to the device.
    pb.getn(4, { |v| x0 = v[0] });
    0.5.wait;
    pb.getn(4, { |v| x1 = v[0] });
    { Out.ar(fb, DC.ar(0.5)) }.play;
    // The drive, loaded again with the device, drives the 0.5 N.
    driveBus = Bus.control(s, 1);
    { Out.kr(driveBus, A2K.kr(FrictionDrive.ar(1))) }.play;
    0.5.wait;
    driveBus.getn(1, { |v| drive = v[0] });
    dev.statusValues({ |v| force = v[\lastForceN] });
    s.sync;
    0.3.wait;
    "KF-POSITION-BUS % %\n".postf(x0, x1);
    "KF-FORCE-BUS %\n".postf(force);
    "KF-DRIVE % %\n".postf(dev.driveSetup.notNil, drive);
    // The monitor of the device's buses reads them again, the pilot's view its new frames.
    before = monitor.frameCount;
    0.5.wait;
    "KF-MONITOR % % %\n".postf(monitor.frameCount - before, monitor.positionMm, monitor.forceN);
    "KF-PILOT-VIEW % %\n".postf(pilot.isPlaying, view.monitor.running);
    view.free; monitor.free; pilot.free;
    s.freeAll;
    [dev, pilotDev].do(_.close);
    strays.do(_.free);
    driveBus.free;
    s.sync;
    "KF-DONE\n".post;
"""


def test_a_reboot_reopens_every_device_with_what_it_holds(jack):
    run = sclang.require_ok(sclang.run_with_server(REBOOT.replace("@DIR@", sclang.sc_string(paths.work_dir())), jack,
                                                   name="reboot", timeout=180))
    print(f"log {run.log_path}")
    assert values(run, "KF-BEFORE ") == [["true", "true", "true", "true"]]
    after = run.output.split("KF-REBOOTING")[1]
    errors = [line for line in after.splitlines()
              if line.startswith("ERROR") or "FAILURE IN SERVER" in line or "not found" in line
              or "no device is open" in line or "not understood" in line]
    # The one error: the device made unable to re-open says so, and the rest of the boot goes on.
    assert len(errors) == 1 and "FrictionDevice(sim, 0) was not opened again after the boot" in errors[0], \
        "\n".join(errors) + f"\nlog {run.log_path}"
    assert values(run, "KF-AFTER-REBOOT ") == [["true", "true", "true", "true", "false"]], "the default group, the devices"
    assert values(run, "KF-SAME-BUSES ") == [["true", "true"]]
    assert values(run, "KF-OVERLAPS ") == [["0"]], run.lines("KF-SHARED ")
    numbers = [[int(n) for n in re.findall(r"\d+", part)] for part in run.output.split("KF-NUMBERS ")[1].splitlines()[0].split("] [")]
    print(f"KF-FIGURE bus_numbers_before_and_after_reboot {numbers}")
    assert all(a != b for a, b in zip(*numbers)), f"the user's boot function moves every bus: {numbers}"
    x0, x1 = (float(v) for v in run.lines("KF-POSITION-BUS ")[0])
    print(f"KF-FIGURE x_mm_on_position_bus_after_reboot {x0} {x1}")
    assert x1 > x0 + 5, "the re-opened simulation moves the puck, and positionBus shows it"
    force = float(run.lines("KF-FORCE-BUS ")[0][0])
    assert abs(force - 0.5) < 1e-3, f"0.5 N played into forceBus reaches the device: {force}"
    # 0.5 N by the table is 1/7 of full scale (2 A), 0.286 A, 0.571 V of 10 V full scale.
    has_drive, drive = run.lines("KF-DRIVE ")[0]
    assert has_drive == "true" and abs(float(drive) - (0.5 - 0.14) / (0.77 - 0.14) * 0.25 * 2 / 0.5 / 10) < 1e-3, drive
    assert "FrictionDrive:" not in run.output, "no drive posts: one is loaded for the device"
    frames, monitor_x, monitor_force = (float(v) for v in run.lines("KF-MONITOR ")[0])
    assert frames >= 5 and monitor_x > 5 and abs(monitor_force - 0.5) < 0.05, (frames, monitor_x, monitor_force)
    assert values(run, "KF-PILOT-VIEW ") == [["true", "true"]]
    assert run.lines("KF-DONE")


def test_a_device_in_a_proxyspace_plays_the_puck_position(jack):
    run = sclang.require_ok(sclang.run_with_server(r"""
        var p = ProxySpace.push(s), vals;
        ~dev = FrictionDevice.sim(s, 2, FrictionHand.speeds([[30, 5]]));
        1.5.wait;
        "KF-PROXY % % %\n".postf(~dev.source.class, ~dev.source.isOpen, ~dev.numChannels);
        ~dev.bus.getn(4, { |v| vals = v });
        s.sync; 0.1.wait;
        "KF-PROXY-X %\n".postf(vals[0]);
        ~dev.source.close;
        p.pop;
    """, jack, name="proxyspace"))
    assert values(run, "KF-PROXY ") == [["FrictionDevice", "true", "4"]]
    assert float(run.lines("KF-PROXY-X ")[0][0]) > 10


def test_a_server_that_ends_while_booting_ends_the_run_with_jacks_word(jack):
    # scsynth whose JACK client is refused ends while booting (a fresh clone's study job saw it:
    # "couldn't activate jack client"); sclang's bootSync then waited until the script's time-out.
    # Here the device names a JACK server that does not run (JACK_NO_START_SERVER keeps it so).
    run = sclang.run_with_server('"KF-NOT-HERE".postln;', jack, timeout=120,
                                 server_options={"device": '"kf-no-such-jack:x"'})
    assert not run.ok
    assert "scsynth ended while booting" in run.output, run.output[-3000:]
    assert "KF-SCRIPT-TIMEOUT" not in run.output and "sclang timed out" not in run.output, run.output[-3000:]
    assert "KF-NOT-HERE" not in run.output
    assert f"jackd {jack.name}'s log" in run.output, run.output[-3000:]
