"""The main job: renders the paper's pilot interaction (section 3, Table 1, Figures 2 and 3)
with FrictionPilot on a simulated device in NRT, for each mapping with friction off and on,
and writes audio, force, CSV, figures and a summary to out/pilot/.

Usage: scripts/pilot/main_job.py [--rate 48000] [--out out/pilot] [--mappings mapping1 ...]
"""
import argparse
import time
from pathlib import Path

import numpy as np

from kfharness import paths, procs, scratch
from kfharness import pilot as P
from kfharness import trace_csv
from view_shot import write_view_shot

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import soundfile  # noqa: E402


def log(msg):
    print(msg, flush=True)


def write_outputs(scene, r, out_dir):
    sr = r["sr"]
    base = out_dir / scene.name
    soundfile.write(f"{base}-audio.wav", np.stack([r["out_left"], r["out_right"]], 1).astype(np.float32), sr, subtype="FLOAT")
    soundfile.write(f"{base}-force.wav", r["commanded_force"].astype(np.float32), sr, subtype="FLOAT")
    trace_csv.write(f"{base}.csv", r, scene.duration_s)
    # Figures 2 and 3: speed, audio, friction against time.
    fig, ax = plt.subplots(3, 1, sharex=True, figsize=(9, 6.5))
    t = r["t"]
    ax[0].plot(t, r["speed"], lw=0.8)
    ax[0].set_ylabel("speed (mm/s)")
    ax[1].plot(t, r["out_left"], lw=0.3)
    ax[1].set_ylabel("audio output")
    ax[1].set_ylim(-1.1, 1.1)
    ax[2].plot(t, r["commanded_force"], lw=0.8)
    ax[2].set_ylabel("friction (N)")
    ax[2].set_ylim(0, 0.6)
    ax[2].set_xlabel("time (s)")
    ins = P.inside(r, scene.origin_mm, scene.explored_mm)
    for a in ax:
        a.fill_between(t, 0, 1, where=ins, transform=a.get_xaxis_transform(), color="0.92", zorder=0)
    spm = scene.samples_per_mm
    fig.suptitle(f"{scene.mapping} ({spm:g} samples/mm), friction {'on' if scene.friction else 'off'}"
                 f" - grey: puck inside the fragment{' (explored part)' if scene.mapping == 'mapping3' else ''}")
    fig.tight_layout()
    fig.savefig(f"{base}.png", dpi=110)
    plt.close(fig)


def analyse(scene, r, session):
    spm = scene.samples_per_mm
    cf = P.cycle_frequencies(r, spm, scene.origin_mm)
    speeds = cf[:, 2] * P.CYCLE_FRAMES / spm if len(cf) else np.zeros(0)
    ins = P.inside(r, scene.origin_mm, scene.explored_mm)
    out = P.outside_for(r, scene.origin_mm, spm, 0.005)
    moving = ins & (np.abs(r["speed"]) >= 40)
    res = dict(
        cycles=len(cf),
        speed_lo=speeds.min() if len(cf) else np.nan, speed_hi=speeds.max() if len(cf) else np.nan,
        f_lo=cf[:, 1].min() if len(cf) else np.nan, f_hi=cf[:, 1].max() if len(cf) else np.nan,
        dev_max=np.max(np.abs(cf[:, 1] / cf[:, 2] - 1)) if len(cf) else np.nan,
        dev_median=np.median(np.abs(cf[:, 1] / cf[:, 2] - 1)) if len(cf) else np.nan,
        crossings=P.crossing_times(r, scene.origin_mm, scene.explored_mm, scene.passes),
        force_moving=np.median(r["force"][moving]) if moving.any() else np.nan,
        outside_audio=np.max(np.abs(r["audio"][out])) if out.any() else np.nan,
        outside_force=(np.min(r["commanded_force"][out]), np.max(r["commanded_force"][out])) if out.any() else (np.nan, np.nan),
        lag_audio=np.nan if not scene.friction else P.lag_samples(r["audio"], r["delayed_audio"], int(0.005 * r["sr"])) / r["sr"],
        # The force of the audio heard (equations (1)-(2) on the delayed output) against the
        # frames the device received (the recording's F lines, at their frame times).
        lag_force_audio=np.nan if not scene.friction else P.lag_samples(
            P.device_force(P.read_session_frames(session), len(r["t"]), r["sr"]),
            P.loudness_force(r["delayed_audio"], r["sr"]), int(0.005 * r["sr"])) / r["sr"],
    )
    # Force peaks per signal cycle crossed (Figure 3: two per cycle at mapping 3).
    if scene.mapping == "mapping3" and scene.friction and len(cf) > 2:
        sr = r["sr"]
        pk_counts = []
        for t0, f_hz, _ in cf:
            a, b = int(t0 * sr), int((t0 + 1 / f_hz) * sr)
            seg = r["force"][a:b]
            pk_counts.append(len(P.peaks(seg, P.MIN_FORCE_N + 0.2, int(0.2 * sr / f_hz))))
        res["peaks_per_cycle"] = (np.median(pk_counts), min(pk_counts), max(pk_counts), len(pk_counts))
    return res


def summary(scenes, results, rate, out_dir, elapsed):
    rendered = [m for m in P.TABLE1 if any(s.mapping == m for s in scenes)]
    L = []
    L.append("# KineticFriction pilot: rendered on the simulated device\n")
    L.append(f"Rendered with scsynth -N at **{rate} Hz** (flag `--rate`; the paper ran at 192 kHz: the loudness "
             f"window is then n = 192 samples, here n = {int(round(rate * 0.001))}). FrictionPilot.score on "
             "FrictionDevice.sim (paper profile: 0.021 mm counts at 125 Hz, 0.14..1.4 N, audio delayed by "
             "tactile - audio latency = 1 ms), hand = FrictionHand.path (a spring-damper hand, 20 N/m, 2 N s/m, "
             "on a 0.1 kg puck with Coulomb friction = the commanded force). The puck starts 10 mm left of the "
             "fragment so that entering it is visible. Each condition: across the fragment fast to the right, back "
             "at a medium speed, across again slowly (Figure 2). Mapping 3 explores the first 100 mm of its 3 m.\n")
    L.append(f"Total time {elapsed:.1f} s.\n")
    L.append("## Audio frequency against Table 1\n")
    L.append("Frequency = speed x samplesPerMm / 100 (100 samples per sine cycle). *Theory*: the formula at the "
             "paper's 2.6 and 334 mm/s, and at the simulated device's speed levels 2.625 and 333.375 mm/s "
             "(1 and 127 counts per 8 ms). *Measured*: every signal cycle crossed in one direction, frequency from "
             "the rendered audio's rising zero crossings, speed = FrictionMouseIn's mean speed over the same "
             "cycle; the range is over the speeds actually used (friction off and on together).\n")
    L.append("| mapping | samples/mm | Table 1 | formula 2.6..334 mm/s | formula 2.625..333.375 mm/s | speeds used (mm/s) "
             "| measured audio (Hz) | formula at those speeds (Hz) | deviation measured vs formula: median (max) | cycles |")
    L.append("|---|---|---|---|---|---|---|---|---|---|")
    for m, row in P.TABLE1.items():
        if m not in rendered:
            continue
        spm = row["samples_per_mm"]
        rs = [results[s.name] for s in scenes if s.mapping == m]
        s_lo = min(x["speed_lo"] for x in rs); s_hi = max(x["speed_hi"] for x in rs)
        f_lo = min(x["f_lo"] for x in rs); f_hi = max(x["f_hi"] for x in rs)
        dev = max(x["dev_max"] for x in rs)
        med = max(x["dev_median"] for x in rs)
        L.append(f"| {m} | {spm} | {row['lo_hz']:g} - {row['hi_hz']:g} Hz "
                 f"| {P.frequency(2.6, spm):.4g} - {P.frequency(334, spm):.5g} "
                 f"| {P.frequency(P.SPEED_STEP, spm):.4g} - {P.frequency(P.MAX_SPEED, spm):.5g} "
                 f"| {s_lo:.1f} - {s_hi:.1f} | {f_lo:.4g} - {f_hi:.5g} | {P.frequency(s_lo, spm):.4g} - {P.frequency(s_hi, spm):.5g} "
                 f"| {100 * med:.3f} % ({100 * dev:.2f} %) | {sum(x['cycles'] for x in rs)} |")
    L.append("\nThe largest single-cycle deviations are at mapping 1's highest frequencies (6 samples per cycle at "
             "48 kHz: locating a zero crossing by linear interpolation) and where the speed level changes within a "
             "cycle.")
    L.append("\nThe measured range is narrower than Table 1's only because the scripts do not use the extreme "
             "speeds (2.6 mm/s would take 2.3 s per mm; near 334 mm/s the sensor saturates).\n")
    L.append("## Crossing times, friction off vs on\n")
    L.append("Time from entering the fragment (for mapping 3: its explored 100 mm) to leaving it on the far side, "
             "same hand script (target speeds in mm/s). Friction binds the hand to slower movements (section 5).\n")
    L.append("| mapping | pass | hand target speed | friction off (s) | friction on (s) | on / off |")
    L.append("|---|---|---|---|---|---|")
    for m in rendered:
        off = results[f"{m}-friction-off"]["crossings"]; on = results[f"{m}-friction-on"]["crossings"]
        for (label, speed, t_off), (_, _, t_on) in zip(off, on):
            L.append(f"| {m} | {label} | {speed:g} mm/s | {t_off:.3f} | {t_on:.3f} | {t_on / t_off:.2f} |")
    L.append("\n## Friction\n")
    L.append(f"Full-scale sine through equations (1)-(2): mean |sin| = 2/pi = {20*np.log10(2/np.pi):.2f} dB -> "
             f"{P.full_scale_sine_force():.4f} N.\n")
    L.append("| condition | median requested force inside, moving >= 40 mm/s (N) | outside: max abs audio | outside: commanded force (N) | audio out behind the audio read (cross-correlation) | force of the heard audio behind the force frames the device got (F lines, cross-correlation) |")
    L.append("|---|---|---|---|---|---|")
    for s in scenes:
        x = results[s.name]
        L.append(f"| {s.name} | {x['force_moving']:.4f} | {x['outside_audio']:.3g} | {x['outside_force'][0]:.3f} - {x['outside_force'][1]:.3f} "
                 + (f"| {1000 * x['lag_audio']:.3f} ms | {1000 * x['lag_force_audio']:.3f} ms |" if s.friction else "| - | - |"))
    L.append("\nOutside: the puck has been outside the fragment (beyond the cubic kernel's one sample) for at least "
             "5 ms. The lags: the paper delays audio by 1 ms (tactile 2.4 ms - audio 1.4 ms latency), so the force sent "
             "to the device leads the sound it was computed from by 1 ms in the render and both arrive together. At "
             "mapping 3 the signals are slow (a few Hz), so the correlation peak is broad.")
    L.append("\nAt mappings 1 and 2 (fast) the force sits near the plateau; at slow speeds (and at mapping 3) a "
             "1 ms window holds less than a cycle, so the force follows |signal| and can reach 0.5 N. A puck "
             "that stops inside the fragment reads a constant sample: its friction stays at that sample's level "
             "(the pilot subjects' \"getting stuck\").\n")
    L.append("## Mapping 3: force cycles per signal cycle (Figure 3)\n")
    L.append("Friction off: the force stays at 0.14 N (no peaks). Friction on:\n")
    for s in scenes:
        pk = results[s.name].get("peaks_per_cycle")
        if pk:
            L.append(f"- {s.name}: median {pk[0]:g} force peaks per signal cycle (min {pk[1]}, max {pk[2]}, over {pk[3]} cycles)")
    L.append("\n## Files\n")
    L.append("Per condition `<mapping>-friction-<off|on>`: `-audio.wav` (stereo, the delayed audio output, float), "
             "`-force.wav` (mono, FrictionOut's commanded force in N, float), `.csv` (every 1 ms: time, position, "
             "speed, audio, delayed audio, requested and commanded force), `.png` (speed, audio, friction against "
             "time, as Figures 2 and 3), `-session.txt` (a kf-session recording of the device: "
             "FrictionDevice.replay(s, path) plays it back).\n")
    (out_dir / "summary.md").write_text("\n".join(L) + "\n")


def main():
    procs.finish_on_sigterm()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rate", type=int, default=48000, help="render sample rate (Hz); the paper used 192000")
    ap.add_argument("--out", default=str(paths.REPO_DIR / "out" / "pilot"))
    ap.add_argument("--mappings", nargs="+", choices=list(P.TABLE1), default=list(P.TABLE1),
                    help="the mappings to render (all three by default; CI renders one)")
    args = ap.parse_args()
    out_dir = Path(args.out).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    start = time.time()
    log(f"== pilot: rendering at {args.rate} Hz into {out_dir}")
    scenes = [P.exploration(m, f) for m in args.mappings for f in (0, 1)]
    results = {}
    for s in scenes:
        t0 = time.time()
        session = out_dir / f"{s.name}-session.txt"
        r = P.render(s, args.rate, record_path=session)
        write_outputs(s, r, out_dir)
        results[s.name] = analyse(s, r, session)
        x = results[s.name]
        log(f"   {s.name}: {s.duration_s:.1f} s rendered in {time.time() - t0:.1f} s; "
            f"audio {x['f_lo']:.4g}..{x['f_hi']:.5g} Hz at {x['speed_lo']:.1f}..{x['speed_hi']:.1f} mm/s; crossings "
            + ", ".join(f"{c[0]} {c[2]:.3f} s" for c in x["crossings"]))
    summary(scenes, results, args.rate, out_dir, time.time() - start)
    # The live view (FrictionView) beside the plots, when a realtime server and a display can run.
    if write_view_shot(out_dir, log):
        with open(out_dir / "summary.md", "a") as f:
            f.write("\n`view.png`: FrictionView (`pilot.view`) in realtime on the simulated device after the puck "
                    "crossed mapping 2's fragment: the signal on the surface, the puck, its speed and the requested "
                    "and commanded force.\n")
    log(f"== pilot done in {time.time() - start:.1f} s. Results: {out_dir} (summary: {out_dir / 'summary.md'})")


if __name__ == "__main__":
    with scratch.for_job():  # its scratch folder removed when it passed
        main()
