"""Every bound of every setting, as a user writes it in sclang, is accepted, and the value just
outside it (the next 32-bit float outward, as sclang sends numbers; the next whole number for
whole settings) is refused with the bound's message. The bounds are read from their one table,
device/core/spec/SettingBounds.cpp."""
import re

import numpy as np

from kfharness import paths, sclang

ROW = re.compile(r'\{"(\w+)", ([-+\d.e]+), ([-+\d.e]+), (true|false), "[^"]*"\}')
REPLAY = {"startS", "rate", "skipIdle", "loop"}
HID = paths.test_data_dir() / "hid" / "genius-gila-gaming-mouse-0458-0138.hid"
# Settings that a bound makes clash with another setting's default: that other setting too, so
# that only the bound is tested.
COMPANIONS = {("minForceN", "max"): {"maxForceN": 50}, ("maxForceN", "min"): {"minForceN": 0},
              ("maxForceN", "below"): {"minForceN": 0}, ("forceFramePeriodS", "max"): {"watchdogS": 10},
              **{("liftEndS", which): {"liftStartS": 0} for which in ("min", "max", "below", "above")}}


def settings():
    text = (paths.REPO_DIR / "device" / "core" / "spec" / "SettingBounds.cpp").read_text()
    rows = [(name, float(lo), float(hi), whole == "true") for name, lo, hi, whole in ROW.findall(text)]
    assert len(rows) > 30, "the bounds table was not read"
    return [r for r in rows if not r[0].startswith("hand")]  # hand script values are not settings


def outside(value, direction, whole):
    """The next 32-bit float beyond the bound (a normal one: a denormal arrives as 0), at least
    the next whole number for whole settings."""
    step = np.nextafter(np.float32(value), np.float32(np.inf if direction > 0 else -np.inf))
    if 0 < abs(step) < np.finfo(np.float32).tiny:
        step = np.float32(direction * np.finfo(np.float32).tiny)
    beyond = float(step)
    if whole:
        beyond = max(beyond, value + 1) if direction > 0 else min(beyond, value - 1)
    return beyond


def sc_number(value):
    """As sclang reads it: a whole number within 32 bits as an Integer, anything else a Float."""
    return str(int(value)) if value == int(value) and abs(value) < 2 ** 31 else repr(float(value))


def test_every_documented_bound_is_accepted_and_the_value_beyond_refused(jack):
    cases = []
    for name, lo, hi, whole in settings():
        for which, value in (("min", lo), ("max", hi), ("below", outside(lo, -1, whole)),
                             ("above", outside(hi, +1, whole))):
            values = {name: value, **COMPANIONS.get((name, which), {})}
            cases.append((name, which, values))
    tries = []
    for name, which, values in cases:
        event = "(" + ", ".join(f"{k}: {sc_number(v)}" for k, v in values.items()) + ")"
        open_call = (f"FrictionDevice.replay(s, {sclang.sc_string(HID)}, 0, {event}, true)" if name in REPLAY
                     else f"FrictionDevice.sim(s, 0, nil, {event}, true)")
        tries.append(f'~try.("{name}", "{which}", {{ {open_call} }});')
    run = sclang.require_ok(sclang.run_with_server(r"""
        var last;
        ~try = { |name, which, open|
            var answer = "ok";
            try { last = open.value } { |error| answer = error.errorString.replace("\n", " ") };
            "KF-BOUND % % %\n".postf(name, which, answer);
        };
        """ + "\n".join(tries) + r"""
        last !? { last.close };
        s.sync;
    """, jack, name="bounds", timeout=300))
    answers = {(f[0], f[1]): " ".join(f[2:]) for f in run.lines("KF-BOUND ")}
    assert len(answers) == len(cases), run.output[-3000:]
    wrong = []
    for name, which, values in cases:
        answer = answers[(name, which)]
        if which in ("min", "max") and answer != "ok":
            wrong.append(f"{name} = {values[name]} ({which}, as documented) refused: {answer}")
        if which in ("below", "above") and not (name in answer and "out of range" in answer):
            wrong.append(f"{name} = {values[name]} ({which} the bound) not refused for its range: {answer}")
    assert not wrong, "\n".join(wrong)
