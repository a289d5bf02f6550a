"""The drive part: the force path of the audio drive (FrictionDrive) beside the board's 1 ms frames
(FrictionOut's commanded force, what the device's frames carry), on one NRT scene: force pulses of
0.5 N above the minimum, 8 ms down to 0.0625 ms wide, each once on a frame border and once half a
frame after it. Per path: the shortest pulse that reaches 90 % of its height at both phases (the
shortest force feature it shows), and the delay of its rising edge behind the request.

The offset between sound and force, for the audio drive, in the same render: the request played
as sound through a DelayL by the drive's audio delay as sclang computes it for the pilot (one
block + FrictionDevice.driveCircuitLatencyOf the drive file, FrictionDevice.driveLatency's sum),
against the drive output's onset, to which the circuit's declared delays are added (no current
source or magnet is in a render: their delays are the file's). So it measures whether the sound
delay the pilot uses puts the sound where the force reaches the magnet: the file read by
sclang, the block FrictionDrive waits, and the delay line's own rounding. The board's realtime
frame latency (its jitter buffer) is not in an NRT render: the e2e part measures it; its sound
delay is the paper's declared tactile - audio latency."""
import numpy as np
import soundfile

from kfharness import drive, nrt, profile

SR = 48000
BLOCK = 64
WIDTHS_MS = [8, 4, 2, 1, 0.5, 0.25, 0.125, 0.0625]
PHASES_MS = [0.0, 0.5]
GAP_MS = 20
HEIGHT_N = 0.5
# A linear magnet and a 4 V channel: sample value = drive level = (force - 0.14 N) / 1.26 N.
MAGNET = [(0.0, 0.14), (1.0, 1.4)]
CIRCUIT = dict(drive.CIRCUIT, outputFullScaleV=4.0, outputSign=1.0, maxSafeCurrentA=2.0)


def request():
    """The requested force (N) and the pulses' (start sample, width in samples, width ms, phase ms)."""
    floor = profile.device()["minForceN"]
    frame = round(profile.device()["forceFramePeriodS"] * SR)  # 48 samples: the frame grid
    force, pulses, t = [], [], 0
    for width_ms in WIDTHS_MS:
        for phase_ms in PHASES_MS:
            # On the frame grid (frames start at whole ms of audio time), then the phase.
            start = -(-(t + round(GAP_MS * SR / 1000)) // frame) * frame + round(phase_ms * SR / 1000)
            width = round(width_ms * SR / 1000)
            force += [floor] * (start - t) + [floor + HEIGHT_N] * width
            pulses.append((start, width, width_ms, phase_ms))
            t = start + width
    force += [floor] * round(GAP_MS * SR / 1000)
    return np.array(force, dtype=np.float32), pulses


def _edge(x, floor, start, fraction):
    """The first sample from `start` at `fraction` of the pulse height or more."""
    above = np.flatnonzero(x[start:] >= floor + HEIGHT_N * fraction)
    return start + int(above[0]) if len(above) else None


def run(bench):
    work = bench.work
    drive_path = drive.write_files(work, circuit=CIRCUIT, magnet=MAGNET, name="bench-drive")
    force, pulses = request()
    force_path = work / "bench-drive-force.wav"
    soundfile.write(str(force_path), force, SR, subtype="FLOAT")
    data, _ = nrt.score_and_render("bench-drive", f"""
        var dev = FrictionDevice.describeSim(0);
        // The pilot's sound delay with this drive (FrictionDevice.driveLatency, in NRT: no server).
        var delay = {BLOCK} / {SR} + FrictionDevice.driveCircuitLatencyOf("{drive_path}");
        var def = SynthDef(\\benchdrive, {{ var f = PlayBuf.ar(1, 10);
            Out.ar(0, [FrictionOut.ar(0, f), FrictionDrive.ar(0), f, DelayL.ar(f, 0.05, delay)]) }});
        score = Score([
            [0.0, dev.openMsg], [0.0, dev.loadDriveMsg("{drive_path}")],
            [0.0, ['/b_allocRead', 10, "{force_path}"]], [0.0, ['/d_recv', def.asBytes]],
            [0.0, Synth.basicNew(\\benchdrive, nil, 1000).newMsg(RootNode(Server.default), nil, \\addToTail)],
            [{len(force) / SR + 0.01}, ['/c_set', 0, 0]]]);
    """, sample_rate=SR, channels=4)
    floor = profile.device()["minForceN"]
    board = data[:, 0].astype(np.float64)
    audio_drive = floor + 1.26 * data[:, 1].astype(np.float64)  # back to N through the linear table
    requested = data[:, 2].astype(np.float64)
    sound = data[:, 3].astype(np.float64)  # the request as sound, delayed as the pilot would
    paths = {"board": board, "drive": audio_drive}
    out = {"pulses": [], "sampleRateHz": SR, "blockSize": BLOCK, "heightN": HEIGHT_N}
    for start, width, width_ms, phase_ms in pulses:
        window = slice(start, start + width + round(0.004 * SR))  # the pulse and 4 ms after it
        entry = {"widthMs": width_ms, "phaseMs": phase_ms}
        for name, x in paths.items():
            entry[name] = float((x[window].max() - floor) / HEIGHT_N)
        out["pulses"].append(entry)
    first = pulses[0][0]
    for name, x in paths.items():
        shows = [w for w in WIDTHS_MS if all(p[name] >= 0.9 for p in out["pulses"] if p["widthMs"] == w)]
        # Onset: the first sample 1 % up (the latency itself); half: 50 % up (with the rise).
        out[name] = {"shortestFeatureMs": min(shows) if shows else None,
                     **{f"{key}DelayMs": (_edge(x, floor, first, f) - _edge(requested, floor, first, f)) * 1000 / SR
                        for key, f in (("onset", 0.01), ("half", 0.5))}}
    dev = profile.device()
    declared = CIRCUIT["currentSourceLatencyS"] + CIRCUIT["magnetLagS"]
    # Onsets (1 % up), as the drive's: where the sound starts and where the force starts to rise.
    sound_onset_ms = (_edge(sound, floor, first, 0.01) - _edge(requested, floor, first, 0.01)) * 1000 / SR
    out["drive"]["declaredMs"] = declared * 1000
    out["drive"]["soundDelayMs"] = sound_onset_ms
    # At the magnet: the drive's output plus the circuit's declared delays; positive: force late.
    out["drive"]["soundForceOffsetMs"] = out["drive"]["onsetDelayMs"] + declared * 1000 - sound_onset_ms
    out["board"]["audioDelayMs"] = (dev["tactileLatencyS"] - dev["audioLatencyS"]) * 1000
    out["board"]["declaredTactileLatencyMs"] = dev["tactileLatencyS"] * 1000
    return out


def summary_lines(d):
    lines = [f"drive vs board (NRT, {d['sampleRateHz'] // 1000} kHz, block {d['blockSize']}, pulses of "
             f"{d['heightN']} N at frame phases 0 and 0.5 ms):"]
    b, a = d["board"], d["drive"]
    lines.append(f"  board 1 ms frames: shortest feature {b['shortestFeatureMs']} ms; commanded force onset "
                 f"{b['onsetDelayMs']:.3f} ms (half height {b['halfDelayMs']:.3f} ms) behind the request, plus the "
                 f"device's realtime frame latency (the paper declares {b['declaredTactileLatencyMs']:.1f} ms tactile); "
                 f"sound delayed {b['audioDelayMs']:.2f} ms")
    lines.append(f"  audio drive: shortest feature {a['shortestFeatureMs']} ms; drive onset {a['onsetDelayMs']:.3f} ms "
                 f"(half height {a['halfDelayMs']:.3f} ms) behind the request, + {a['declaredMs']:.2f} ms declared "
                 f"circuit delays; the pilot's sound delay measured in the render {a['soundDelayMs']:.3f} ms: "
                 f"force - sound {a['soundForceOffsetMs']:+.3f} ms")
    lines.append("  peak reached (fraction of the pulse) by width ms/phase ms: " + ", ".join(
        f"{p['widthMs']}/{p['phaseMs']}: board {p['board']:.2f} drive {p['drive']:.2f}" for p in d["pulses"]))
    return lines


def report_tables(d, table):
    """REPORT.md's tables (report.py's `table`): the two paths side by side, and each pulse."""
    b, a = d["board"], d["drive"]
    rows = [("board, 1 ms frames", b["shortestFeatureMs"], f"{b['onsetDelayMs']:.3f}", f"{b['halfDelayMs']:.3f}",
             f"the realtime frame latency (paper: {b['declaredTactileLatencyMs']:.1f} ms tactile)",
             f"{b['audioDelayMs']:.3f} (declared)", "-"),
            ("audio drive", a["shortestFeatureMs"], f"{a['onsetDelayMs']:.3f}", f"{a['halfDelayMs']:.3f}",
             f"{a['declaredMs']:.3f} (the circuit's declared delays)", f"{a['soundDelayMs']:.3f} (measured)",
             f"{a['soundForceOffsetMs']:+.3f}")]
    paths = table(["path", "shortest feature (ms)", "force onset behind request (ms)", "half height (ms)",
                   "added outside the render (ms)", "sound delay (ms)", "force - sound (ms)"], rows)
    pulses = table(["width (ms)", "phase (ms)", "board peak", "drive peak"],
                   [(p["widthMs"], p["phaseMs"], f"{p['board']:.2f}", f"{p['drive']:.2f}") for p in d["pulses"]])
    return paths, pulses
