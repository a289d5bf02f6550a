"""Friction that steers: SpeedGovernor on the simulated device brings the puck's speed to the
target. The simulated hand pushes with a constant force (FrictionHand.force), so its speed is set
by friction alone: Coulomb friction against a push P holds the puck where the governor's force
equals P, at target + (P - loForce) / gain; with the resting force alone it accelerates until the
sensor saturates (334 mm/s)."""
import numpy as np

from kfharness import nrt

SR = 48000
PUSH_N, LO_N, HI_N = 0.25, 0.14, 1.4
SECONDS = 1.5


def render(target, gain, governed=True):
    """FrictionMouseIn's x and speed and the commanded force (N)."""
    force = f"SpeedGovernor.ar(m[2], m[3], {target}, {gain}, {LO_N}, {HI_N})" if governed else f"DC.ar({LO_N})"
    data, _ = nrt.score_and_render(f"governor-{target}-{gain}-{int(governed)}", f"""
        var dev = FrictionDevice.sim(nil, 0, FrictionHand.force({PUSH_N}));
        var def = SynthDef(\\governor, {{
            var m = FrictionMouseIn.ar(0, 0, 1);
            Out.ar(0, [m[0], m[2], FrictionOut.ar(0, {force})])
        }});
        score = Score([
            [0.0, dev.openMsg],
            [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\governor, nil, 1000).newMsg],
            [{SECONDS}, ['/n_free', 1000]],
            [{SECONDS}, dev.closeMsg]]);
    """, channels=3)
    return data[: nrt.bundle_start_sample(SECONDS, SR)].astype(np.float64)


def test_the_governor_brings_the_pushed_puck_to_the_target_speed():
    free = render(0, 0, governed=False)
    free_speed = free[int(0.5 * SR):, 1].mean()
    # Resting friction only: (0.25 - 0.14) N / 0.1 kg = 1.1 m/s^2, past the sensor's 334 mm/s by 0.3 s.
    assert free_speed > 320, free_speed
    for target, gain in [(80, 0.01), (40, 0.005)]:
        r = render(target, gain)
        speed = r[int(0.5 * SR):, 1]
        settled = target + (PUSH_N - LO_N) / gain  # 91 and 62 mm/s
        # Measured (this commit): 91.0 and 62.0 mm/s mean over 0.5..1.5 s, standard deviation
        # 1.2 and 1.3 mm/s. Within 3 mm/s: a count (0.021 mm) per 8 ms report is 2.6 mm/s.
        assert abs(speed.mean() - settled) < 3, (target, gain, speed.mean())
        assert speed.std() < 5
        # The commanded force is the push (the puck neither speeds up nor slows down on average).
        assert abs(r[int(0.5 * SR):, 2].mean() - PUSH_N) < 0.01
        assert speed.mean() < free_speed / 3
