"""Friction that steers: SpeedGovernor on the simulated device brings the puck's speed towards the
target. A hand pushing with a constant force (FrictionHand.force) has its speed set by friction
alone: Coulomb friction against a push P holds the puck where the governor's force equals P, at
target + (P - loForce) / gain; with the resting force alone it accelerates until the sensor
saturates (334 mm/s). A hand pulling through its spring is slowed until its pull wins. One render:
every case on a slot of its own."""
import numpy as np

from kfharness import nrt

SR = 48000
PUSH_N, LO_N, HI_N = 0.25, 0.14, 1.4
SECONDS = 1.5
PUSH, PULL = f"FrictionHand.force({PUSH_N})", "FrictionHand.speeds([[200, 2]])"
CASES = [  # (hand, target mm/s, gain N per mm/s, or None: the resting force alone)
    (PUSH, None, None), (PUSH, 80, 0.01), (PUSH, 40, 0.005), (PULL, None, None), (PULL, 80, 0.01)]


def render():
    """Per case: FrictionMouseIn's speed along x and the commanded force (N), from 0.5 s on."""
    opens, outs = [], []
    for slot, (hand, target, gain) in enumerate(CASES):
        opens.append(f"[0.0, FrictionDevice.describeSim({slot}, {hand}).openMsg]")
        force = f"SpeedGovernor.ar(m[2], m[3], {target}, {gain}, {LO_N}, {HI_N})" if gain else f"DC.ar({LO_N})"
        outs.append(f"{{ var m = FrictionMouseIn.ar({slot}, 0, 1); [m[2], FrictionOut.ar({slot}, {force})] }}.value")
    data, _ = nrt.score_and_render("governor", f"""
        var def = SynthDef(\\governor, {{ Out.ar(0, [{", ".join(outs)}].flat) }});
        score = Score([{", ".join(opens)},
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\governor, nil, 1000).newMsg],
            [{SECONDS}, ['/n_free', 1000]]]);
    """, channels=2 * len(CASES))
    data = data[int(0.5 * SR): nrt.bundle_start_sample(SECONDS, SR)].astype(np.float64)
    return [(data[:, 2 * k], data[:, 2 * k + 1]) for k in range(len(CASES))]


def test_the_governor_brings_the_speed_towards_the_target():
    cases = render()
    free_speed = cases[0][0].mean()
    # Resting friction only: (0.25 - 0.14) N / 0.1 kg = 1.1 m/s^2, past the sensor's 334 mm/s by 0.3 s.
    assert free_speed > 320, free_speed
    for (_, target, gain), (speed, force) in zip(CASES[1:3], cases[1:3]):
        settled = target + (PUSH_N - LO_N) / gain  # 91 and 62 mm/s
        # Measured (tests' commit): 91.0 and 62.0 mm/s mean over 0.5..1.5 s, standard deviations
        # 1.2 and 1.3 mm/s. Within 3 mm/s: a count (0.021 mm) per 8 ms report is 2.6 mm/s.
        assert abs(speed.mean() - settled) < 3, (target, gain, speed.mean())
        assert speed.std() < 5
        # The commanded force is the push: the puck neither speeds up nor slows down on average.
        assert abs(force.mean() - PUSH_N) < 0.01
    # A hand whose target runs at 200 mm/s pulls through its spring (20 N/m, up to 1.5 N): it lags
    # more as friction rises and pulls harder, so the governor slows it until the pull reaches
    # hiForce. Measured (help: SpeedGovernor): 168 mm/s over 0.5..1.0 s, 186 over 1.0..1.5 s, 200
    # without the governor.
    half = int(0.5 * SR)
    free, governed = cases[3][0][:half].mean(), cases[4][0][:half].mean()
    assert abs(free - 200) < 3 and governed < free - 20, (free, governed)
