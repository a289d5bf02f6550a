"""The audio drive (FrictionDrive) in Python, for the tests and the bench: a kf-drive file and its
magnet table written out, and the reference of what the plugin computes from the slot's combined
force, sample by sample (the board's safety path with a frame of one sample, the magnet table,
current -> volts -> sample value; device/core/force/AudioDrive.cpp), in the same double
arithmetic."""
import numpy as np

from . import profile

# A magnet measured at four currents (fractions of fullScaleCurrentA): force (N) at drive levels.
MAGNET = [(0.0, 0.14), (0.25, 0.41), (0.5, 0.72), (1.0, 1.4)]
# 2 A full scale through 0.5 A/V: 4 V of a 10 V channel, inverted; safe to 1.8 A (drive 0.9).
CIRCUIT = dict(fullScaleCurrentA=2.0, transconductanceAPerV=0.5, outputFullScaleV=10.0, outputSign=-1.0,
               maxSafeCurrentA=1.8, currentSourceLatencyS=0.00002, magnetLagS=0.0004)


def write_files(folder, circuit=CIRCUIT, magnet=MAGNET, name="drive", separator=" "):
    """Writes <name>.kfdrive (its fields separated by `separator`) and its magnet table
    <name>-magnet.kfcal in folder; the drive's path."""
    table = folder / f"{name}-magnet.kfcal"
    table.write_text("kf-calibration 1\n" + "".join(f"{d!r} {f!r}\n" for d, f in magnet))
    path = folder / f"{name}.kfdrive"
    path.write_text(f"kf-drive 1\nmagnetTable {table.name}\n" + "".join(f"{k}{separator}{v!r}\n" for k, v in circuit.items()))
    return path


def combined_force(writers, min_force_n=None):
    """SlotForce's rule per sample: minForce + sum of max(0, force - minForce), NaN/Inf adding
    nothing; float32 as the slot keeps it."""
    min_n = profile.device()["minForceN"] if min_force_n is None else min_force_n
    excess = np.zeros(len(writers[0]))
    for force in writers:
        f = np.asarray(force, dtype=np.float32).astype(np.float64)
        excess += np.where(np.isfinite(f) & (f > min_n), f - min_n, 0.0)
    return (min_n + excess).astype(np.float32)


def _drive_for_force(force_n, magnet):
    """CalibrationTable::driveForForce: the least drive giving force_n."""
    drives = [d for d, _ in magnet]
    forces = [f for _, f in magnet]
    if not force_n > forces[0]:
        return drives[0]
    if force_n >= forces[-1]:
        return next(d for d, f in magnet if f >= forces[-1])
    i = next(k for k, f in enumerate(forces) if f >= force_n)
    if forces[i] == force_n:
        return drives[i]
    fraction = (force_n - forces[i - 1]) / (forces[i] - forces[i - 1])
    return min(max(drives[i - 1] + fraction * (drives[i] - drives[i - 1]), drives[i - 1]), drives[i])


def reference(combined, framed, block_size, sample_rate, circuit=CIRCUIT, magnet=MAGNET, spec=None):
    """The drive's samples: combined (per sample, float32) is driven one block late; framed[b] says
    whether block b was framed (a writer ran), else the block after it is 0 and the slew starts
    again from the minimum. Heat derating is left out: the callers' scenes stay far below it
    (heatTimeConstantS 30 s), and say so."""
    spec = spec or profile.device()
    min_n, max_n = spec["minForceN"], spec["maxForceN"]
    min_f, max_f = float(np.float32(min_n)), float(np.float32(max_n))
    step_n = spec["maxForceSlewNPerS"] * (1.0 / sample_rate)
    safe = min(max(circuit["maxSafeCurrentA"] / circuit["fullScaleCurrentA"], 0.0), 1.0)
    limit = min(spec["maxDriveLevel"], safe)
    per_drive = circuit["fullScaleCurrentA"] / circuit["transconductanceAPerV"]
    out = np.zeros(len(combined), dtype=np.float32)
    slewed = min_n
    for n in range(block_size, len(combined)):
        b = n // block_size
        if not framed[b - 1]:
            slewed = min_n
            continue
        target = float(combined[n - block_size])
        if not np.isfinite(target):
            target = min_n
        target = min(max(target, min_n), max_n)
        if target <= min_f:
            target = min_n
        if target >= max_f:
            target = max_n
        target = min(max(target, slewed - step_n), slewed + step_n)
        slewed = target
        drive = min(_drive_for_force(target, magnet), limit)
        drive = min(float(np.float32(min(max(drive, 0.0), 1.0))), safe)
        volts = drive * per_drive
        out[n] = circuit["outputSign"] * min(max(volts / circuit["outputFullScaleV"], 0.0), 1.0)
    return out
