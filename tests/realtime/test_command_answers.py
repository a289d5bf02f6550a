"""Every plugin command answers once, whatever is wrong with it: `/done cmdName` or `/kfFail`
naming the command, the device (the reply ID) and the reason. A table of malformed commands,
every command x wrong type, missing argument, extra argument, out-of-range device, unknown
setting, over-long string and empty string, is sent raw to a realtime server; after each, a
/sync (answered only when every asynchronous command before it has finished) closes the count.
The server still renders afterwards, and the FrictionDevice methods raise the server's reason."""
import math

from kfharness import paths, sclang

HID = str(paths.test_data_dir() / "hid" / "genius-gila-gaming-mouse-0458-0138.hid")
LONG = object()  # a 5,000-character string (the recording path)
NAN, INF = float("nan"), float("inf")

# A well-formed message of each command on device 0 (open: a simulated device, no board).
VALID = {
    "kfOpenSim": [0, -1, 0, "replace", 1],
    "kfOpenReplay": [0, HID, "replace", 1],
    "kfRecord": [0, "/nonexistent-dir/session.txt"],
    "kfStatus": [0, 0],
    "kfClose": [0],
    "kfZero": [0, 1.0, 2.0],
    "kfListMice": ["hidapi", ""],
    "kfOpenMouse": [0, "", "hidapi", ""],
    "kfReopenMouse": [0],
    "kfBoardOpen": [0, "", 1, 2],
    "kfBoardArm": [0, 1],
    "kfBoardCalibrate": [0, ""],
    "kfBoardClose": [0],
    "kfBoardStatus": [0],
    "kfDriveCalibrate": [0, ""],
}
TAKES_SETTINGS = {"kfOpenSim", "kfOpenReplay", "kfOpenMouse"}
HAS_DEVICE = set(VALID) - {"kfListMice"}


def variants(cmd):
    """(variant, args, must_fail, expected text) for one command; must_fail False: a variant that
    is well-formed for this command (one answer is all that is asserted)."""
    args = VALID[cmd]
    strings = [i for i, a in enumerate(args) if isinstance(a, str)]

    def with_strings(value):
        return [value if i in strings else a for i, a in enumerate(args)] if strings else [value] + args[1:]

    yield "wrong type", (["one"] + args[1:] if cmd in HAS_DEVICE else [3] + args[1:]), True, ""
    # kfZero's coordinates and kfStatus's post flag are optional: without them it is still a command.
    yield "missing", args[:-1], cmd not in {"kfZero", "kfStatus"}, ""
    yield "extra", args + [7], True, "argument" if cmd not in TAKES_SETTINGS else "setting name"
    if cmd in HAS_DEVICE:
        for device in (16, -1, 2.5, NAN, INF):
            yield f"device {device}", [device] + args[1:], True, "device"
    yield "unknown setting", args + ["noSuchSetting", 1], True, "noSuchSetting" if cmd in TAKES_SETTINGS else ""
    yield "over-long string", with_strings(LONG), True, "longer than" if strings else "string"
    # An empty string is valid where "" means something (stop recording, the first board, both
    # backends, linear calibration, no audio drive), refused elsewhere.
    yield "empty string", with_strings(""), cmd in {"kfOpenReplay", "kfOpenSim"} or not strings, ""


def sc_value(value):
    if value is LONG:
        return 'String.fill(5000, $x)'
    if isinstance(value, str):
        return sclang.sc_string(value)
    if isinstance(value, float) and math.isnan(value):
        return "(0.0/0.0)"
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    return repr(value)


CASES = [(cmd, name, args, must_fail, text) for cmd in VALID for name, args, must_fail, text in variants(cmd)]


def test_every_malformed_command_gets_one_answer_and_the_server_renders_on(jack):
    sends = "\n".join(
        f'~case.({i}, [\\{cmd}, {", ".join(sc_value(a) for a in args)}]);' for i, (cmd, _, args, _, _) in enumerate(CASES))
    run = sclang.require_ok(sclang.run_with_server(r"""
        var answers = List.new, alive = 0, synth, dev;
        OSCFunc({ |m| answers.add(["done", m[1], -1, ""]) }, '/done', s.addr);
        OSCFunc({ |m| answers.add(["fail", "", m[2], m[3..].collect { |c| c.asInteger.asAscii }.join]) },
            '/kfFail', s.addr);
        ~case = { |i, msg|
            answers.clear;
            s.listSendMsg(['/cmd'] ++ msg);
            s.sync;
            "KF-ANSWERS % %\n".postf(i, answers.size);
            answers.do { |a| "KF-ANSWER % % % %\n".postf(i, a[0], a[2], a[3].replace("\n", " ")) };
        };
        s.listSendMsg(['/cmd', \kfOpenSim, 0, -1, 0]);
        s.sync;
        """ + sends + r"""
        // The server still renders: a synth's replies come at its 100 Hz.
        OSCFunc({ alive = alive + 1 }, '/kfAlive', s.addr);
        synth = { SendReply.kr(Impulse.kr(100), '/kfAlive', SinOsc.ar(440)); Silent.ar }.play;
        0.5.wait;
        synth.free;
        "KF-ALIVE %\n".postf(alive);
        // FrictionDevice raises the server's reason, not a time-out.
        dev = FrictionDevice.sim(s, 1);
        try { dev.record("/tmp/" ++ String.fill(5000, $x)) } { |e| "KF-RAISED record %\n".postf(e.errorString) };
        try { dev.arm } { |e| "KF-RAISED arm %\n".postf(e.errorString) };
        try { dev.addBoard("NO-SUCH-BOARD") } { |e| "KF-RAISED addBoard %\n".postf(e.errorString) };
        dev.close;
        s.sync;
        // A refused statusValues leaves no responder awaiting a /kfStatus that will not come.
        // kfStatus answers every slot, open or not, so the object is made to name slot 16.
        dev.instVarPut(\index, 16);
        try { dev.statusValues { "KF-STATUS-CAME\n".post } } { |e| "KF-RAISED status %\n".postf(e.errorString) };
        "KF-STATUS-RESPONDERS %\n".postf(OSCFunc.allFuncProxies.values.flatten.count { |f|
            f.respondsTo(\path) and: { f.path == '/kfStatus' } });
    """, jack, name="answers", timeout=240))
    counts = {int(f[0]): int(f[1]) for f in run.lines("KF-ANSWERS ")}
    answers = {}
    for f in run.lines("KF-ANSWER "):
        answers.setdefault(int(f[0]), []).append((f[1], int(f[2]), " ".join(f[3:])))
    assert len(counts) == len(CASES), run.output[-3000:]
    wrong = []
    for i, (cmd, name, args, must_fail, text) in enumerate(CASES):
        got = answers.get(i, [])
        what = f"{cmd} {name}"
        if counts[i] != 1:
            wrong.append(f"{what}: {counts[i]} answers {got}")
            continue
        kind, reply_id, reason = got[0]
        if kind == "fail" and not reason.startswith(cmd + ":"):
            wrong.append(f"{what}: the refusal does not name its command: {reason!r}")
        if must_fail and kind != "fail":
            wrong.append(f"{what}: accepted")
        if kind == "fail" and text and text not in reason:
            wrong.append(f"{what}: the reason does not say '{text}': {reason!r}")
        # The device is the reply ID where it could be read, -1 where it is what was wrong.
        device = args[0] if args else None
        device_ok = cmd in HAS_DEVICE and isinstance(device, int) and 0 <= device < 16
        if kind == "fail" and reply_id != (device if device_ok else -1):
            wrong.append(f"{what}: reply ID {reply_id} for device argument {device!r}")
    assert not wrong, f"{len(wrong)} of {len(CASES)} cases:\n" + "\n".join(wrong)
    # 50 replies in 0.5 s on an idle machine; >= 10 leaves 0.4 s for a loaded one's delays.
    alive = run.lines("KF-ALIVE ")
    assert alive and int(alive[0][0]) >= 10, run.output[-2000:]
    raised = {f[0]: " ".join(f[1:]) for f in run.lines("KF-RAISED ")}
    assert "longer than" in raised.get("record", ""), raised
    assert "has no board" in raised.get("arm", ""), raised
    assert "kfBoardOpen" in raised.get("addBoard", "") and "no answer" not in raised["addBoard"], raised
    assert "kfStatus" in raised.get("status", "") and "device" in raised["status"], raised
    assert run.lines("KF-STATUS-RESPONDERS ") == [["0"]], run.output[-2000:]
