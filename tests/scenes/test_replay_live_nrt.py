"""Replay for live use (issue 14): skip the idle lead-in, start at a time, loop, rate. A session
with 2 s of idle lead-in is recorded from the simulated device, then replayed in Scores."""
import numpy as np

from kfharness import nrt, paths

SR = 48000
SESSION = paths.work_dir() / "idle-lead-in.kfs"


def record_session():
    if SESSION.exists():
        return
    nrt.score_and_render("recordidle", f"""
        var dev = FrictionDevice.describeSim(0, FrictionHand.path([[0, 0], [2, 0], [3, 30], [3.5, 30]]));
        var def = SynthDef(\\recordidle, {{ Out.ar(0, FrictionMouseIn.ar(0)[0]) }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, dev.recordMsg("{SESSION}")],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\recordidle, nil, 1000).newMsg],
            [3.6, dev.closeMsg],
            [3.65, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=1)


def replay_x(name, profile, seconds):
    record_session()
    data, _ = nrt.score_and_render(name, f"""
        var dev = FrictionDevice.describeReplay("{SESSION}", 0, {profile});
        var def = SynthDef(\\{name}, {{ Out.ar(0, FrictionMouseIn.ar(0)[0]) }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\{name}, nil, 1000).newMsg],
            [{seconds}, dev.closeMsg],
            [{seconds} + 0.05, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=1)
    x = data[:, 0].astype(np.float64)
    return x[: int(seconds * SR)]


def at(x, t):
    return x[int(t * SR)]


def test_plain_replay_plays_the_idle_lead_in():
    x = replay_x("replayplain", "nil", 4.0)
    assert at(x, 1.5) == 0.0
    final = at(x, 3.9)
    print(f"KF-FIGURE replay_plain_x_at_1.5s {at(x, 1.5)} final {final}")
    assert final > 20


def test_skip_idle_starts_with_the_movement_and_ends_at_the_same_position():
    plain = replay_x("replayplain2", "nil", 4.0)
    x = replay_x("replayskip", "(skipIdle: true)", 2.0)
    print(f"KF-FIGURE replay_skipIdle_x_at_0.5s {at(x, 0.5):.3f} (plain {at(plain, 0.5):.3f})")
    assert at(x, 0.5) > 5
    assert at(x, 1.9) == at(plain, 3.9), "the same recorded path"


def test_start_time_and_rate():
    plain = replay_x("replayplain3", "nil", 4.0)
    x = replay_x("replayrate", "(startS: 2, rate: 2)", 1.0)
    # File time 2 + 2 t is played at t: half-way through the movement at 0.25 s.
    for t in (0.1, 0.25, 0.4):
        assert abs(at(x, t) - at(plain, 2 + 2 * t)) < 1.0, (t, at(x, t), at(plain, 2 + 2 * t))
    print(f"KF-FIGURE replay_rate2_x_at_0.25s {at(x, 0.25):.3f} plain_at_2.5s {at(plain, 2.5):.3f}")
    assert at(x, 0.95) == at(plain, 3.9)


def test_loop_plays_again_and_the_position_carries_on():
    plain = replay_x("replayplain4", "nil", 4.0)
    final = at(plain, 3.9)
    x = replay_x("replayloop", "(skipIdle: true, loop: true)", 5.0)
    print(f"KF-FIGURE replay_loop_x_at_4.9s {at(x, 4.9):.3f} one_pass {final:.3f}")
    assert at(x, 4.9) > 2.5 * final  # three passes of ~1.6 s (file 1.99 .. 3.6 s)
