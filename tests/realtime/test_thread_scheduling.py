"""The device's threads on a running scsynth (JACK dummy, `jackd -R` where this user may): named
after their role and slot, so that `ps -L` shows them, SCHED_FIFO one above scsynth's audio
thread where realtime is allowed, at normal priority when a device asks for it, and the same
in the /kfStatus reply (FrictionDevice.statusValues)."""
from kfharness import sclang, status
from kfharness.load import realtime_allowed


def threads_of(ps_lines):
    """[(name, class, rtprio)] from `ps -L -o cls=,rtprio=,comm=` lines."""
    return [(f[2], f[0], None if f[1] == "-" else int(f[1])) for f in ps_lines if len(f) == 3]


def test_threads_are_named_and_realtime_above_the_audio_thread(jack):
    run = sclang.require_ok(sclang.run_with_server("var rt, normal;\n" + status.SC_POST + r"""
        rt = FrictionDevice.sim(s, 3, FrictionHand.speeds([[20, 5]]));
        normal = FrictionDevice.sim(s, 4, FrictionHand.speeds([[20, 5]]), (threadPriority: 0));
        s.sync;
        rt.addBoard(emulate: true);
        s.sync;
        0.5.wait;
        ("ps -L -o cls=,rtprio=,comm= -p " ++ s.pid).unixCmdGetStdOut.split($\n).do { |l| ("KF-PS " ++ l ++ "\n").post };
        [rt, normal].do { |d| ~kfPostStatus.(d, "KF-STATUS") };
        rt.status;
        s.sync;
        rt.removeBoard;
        [rt, normal].do(_.close);
        s.sync;
    """, jack, name="scheduling"))
    listed = threads_of(run.lines("KF-PS "))
    threads = {name: (cls, priority) for name, cls, priority in listed if name.startswith("kf-")}
    figures = status.parse(run.output, "KF-STATUS")
    assert {"kf-device-3", "kf-usb-3", "kf-device-4"} <= set(threads), threads
    assert figures[4]["deviceThreadPriority"] == 0
    assert threads["kf-device-4"] == ("TS", None)
    # Device 4 was only polled (statusValues): its figures came, nothing was posted.
    assert not [line for line in run.output.splitlines() if line.startswith("kfStatus 4:")], run.output[-2000:]
    assert [line for line in run.output.splitlines() if line.startswith("kfStatus 3:")], "status posts"
    if realtime_allowed():
        # jackd -R -P 70: scsynth's audio thread (a JACK client's) at SCHED_FIFO 65, ours at 66.
        audio = max(p for name, cls, p in listed if name == "scsynth" and cls == "FF")
        assert threads["kf-device-3"] == ("FF", audio + 1)
        assert threads["kf-usb-3"] == ("FF", audio + 1)
        assert figures[3]["deviceThreadPriority"] == audio + 1
        assert figures[3]["usbThreadPriority"] == audio + 1
        assert "threads: device SCHED_FIFO %d" % (audio + 1) in run.output
        assert figures[3]["memoryLocked"] == 1  # as root; a user needs the memlock limit
        # The rest of the server at normal priority: booted from sclang's SystemClock thread it
        # would run SCHED_FIFO 1, every thread but JACK's (kfharness.sclang.server_program_code).
        assert listed[0][:2] == ("scsynth", "TS") and ("scsynth", "FF", 1) not in listed, listed
    else:
        assert threads["kf-device-3"][0] == "TS"
        assert figures[3]["deviceThreadPriority"] == 0
        assert "realtime scheduling (SCHED_FIFO" in run.output  # the one message with the fix
    assert figures[3]["mouseThreadPriority"] == -1  # a simulated device reads no mouse
    assert figures[3]["open"] == 1 and figures[3]["realtime"] == 1
    assert figures[3]["reports"] >= 30  # 0.5 s and more of 125 Hz reports: the thread runs
