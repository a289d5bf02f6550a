#!/usr/bin/python3
"""Writes the synthetic hid-recorder recordings of tests/data/hid/ from one known physical
trajectory, as four mice would report it: a 125 Hz boot-like mouse with 8-bit axes, a 1 kHz
gaming mouse with 12-bit axes, a 8 kHz gaming mouse with 16-bit axes and a 250 Hz wireless mouse
that sends its buttons in a report of their own (tests/data/hid/README.md says what each file is). Also writes the trajectory itself (synthetic-trajectory.csv), which the
tests and the report-rate bench compare the replayed position with.

    /usr/bin/python3 tests/data/hid/make_synthetic.py            # rewrites the files beside it

Deterministic: the same files every time (no randomness, fixed formatting).

The sensor model: at each poll (every 1/rate s from t = 0) the sensor's count position is
round(position / count size) per axis; the report carries its change since the last poll. A
change beyond the report field's logical limit is sent at the limit and the excess is lost (the
sensor's reference moves on to the new position), as a boot-protocol mouse's firmware does. A
mouse sends a report only when it has moved or a button changed (no report while still). The
report's time is the poll's (the host's arrival time, no USB jitter), printed to the microsecond
as hid-recorder prints it.
"""
import math
from pathlib import Path

HERE = Path(__file__).resolve().parent
DURATION_S = 1.4
MOTION_START_S, MOTION_S = 0.2, 1.0
TRUTH_STEP_S = 0.0005

# X: a raised-cosine sweep 0..40 mm whose frequency rises linearly from 0.5 to 4.5 Hz in 1 s:
# 2.5 strokes, ending at rest at 40 mm; its speed peaks at 537 mm/s (beyond the 333 mm/s a
# 125 Hz report of 8-bit counts of 0.021 mm carries). Y: 1.5 periods of a 1.5 Hz raised cosine,
# 0 to -12 mm, ending at rest at -12 mm (57 mm/s at most).
X_AMPLITUDE_MM, X_F0_HZ, X_F1_HZ = 20.0, 0.5, 4.5
Y_AMPLITUDE_MM, Y_F_HZ = -6.0, 1.5
# (start s, end s, button bits): a click before the movement, the left button held during it,
# a right click after it.
BUTTONS = [(0.05, 0.10, 1), (0.50, 0.70, 1), (1.25, 1.30, 2)]


def position_mm(t):
    """The puck's true (x, y) in mm at time t s, along the mouse's report axes +X and +Y."""
    u = min(max(t - MOTION_START_S, 0.0), MOTION_S)
    phase = 2 * math.pi * (X_F0_HZ * u + (X_F1_HZ - X_F0_HZ) * u * u / (2 * MOTION_S))
    return (X_AMPLITUDE_MM * (1 - math.cos(phase)), Y_AMPLITUDE_MM * (1 - math.cos(2 * math.pi * Y_F_HZ * u)))


def buttons_at(t):
    bits = 0
    for start, end, b in BUTTONS:
        if start <= t < end:
            bits |= b
    return bits


def le(value, size_bytes):
    return list((value & ((1 << (8 * size_bytes)) - 1)).to_bytes(size_bytes, "little"))


# --- the three mice: descriptor, fields, and how one report is packed -------------------------

# 125 Hz boot-like mouse, no report IDs: 3 buttons and 5 bits of padding, then X, Y and a wheel,
# each 8 bits, logical -127..127.
BOOT_DESCRIPTOR = [
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01,  # Generic Desktop, Mouse, Application
    0x09, 0x01, 0xA1, 0x00,  # Pointer, Physical
    0x05, 0x09, 0x19, 0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02,  # 3 buttons
    0x95, 0x01, 0x75, 0x05, 0x81, 0x01,  # 5 bits constant
    0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x09, 0x38,  # X, Y, Wheel
    0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x03, 0x81, 0x06,  # -127..127, 8 bits x 3, relative
    0xC0, 0xC0,
]


def boot_report(buttons, dx, dy, buttons_changed):
    return [[buttons & 7] + le(dx, 1) + le(dy, 1) + [0]]


# 1 kHz gaming mouse, report ID 2: 16 buttons, X and Y as 12-bit fields packed in 3 bytes
# (logical -2047..2047), wheel and AC pan 8 bits; then a vendor collection (usage page 0xFF00)
# with a 7-byte and a 20-byte input and output report (IDs 0x10, 0x11, as vendor protocols for
# the mouse's settings have) and a 63-byte feature report (ID 0x20).
GAMING_12_DESCRIPTOR = [
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x85, 0x02,  # Mouse, Application, report ID 2
    0x09, 0x01, 0xA1, 0x00,
    0x05, 0x09, 0x19, 0x01, 0x29, 0x10, 0x15, 0x00, 0x25, 0x01, 0x95, 0x10, 0x75, 0x01, 0x81, 0x02,  # 16 buttons
    0x05, 0x01, 0x16, 0x01, 0xF8, 0x26, 0xFF, 0x07, 0x75, 0x0C, 0x95, 0x02, 0x09, 0x30, 0x09, 0x31,  # -2047..2047
    0x81, 0x06,  # X, Y: 12 bits x 2, relative
    0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x01, 0x09, 0x38, 0x81, 0x06,  # wheel
    0x05, 0x0C, 0x0A, 0x38, 0x02, 0x95, 0x01, 0x81, 0x06,  # AC pan
    0xC0, 0xC0,
    0x06, 0x00, 0xFF, 0x09, 0x01, 0xA1, 0x01,  # vendor page 0xFF00, Application
    0x85, 0x10, 0x75, 0x08, 0x95, 0x06, 0x15, 0x00, 0x26, 0xFF, 0x00,  # ID 0x10: 6 bytes
    0x09, 0x01, 0x81, 0x00, 0x09, 0x01, 0x91, 0x00,  # input, output
    0x85, 0x11, 0x95, 0x13, 0x09, 0x02, 0x81, 0x00, 0x09, 0x02, 0x91, 0x00,  # ID 0x11: 19 bytes
    0x85, 0x20, 0x95, 0x3E, 0x09, 0x03, 0xB1, 0x02,  # ID 0x20: 62-byte feature
    0xC0,
]


def gaming_12_report(buttons, dx, dy, buttons_changed):
    packed = (dx & 0xFFF) | (dy & 0xFFF) << 12
    return [[0x02] + le(buttons, 2) + le(packed, 3) + [0, 0]]


# 8 kHz gaming mouse, report ID 1: 5 buttons and 3 bits of padding, X and Y 16 bits (logical
# -32767..32767), wheel 8 bits and AC pan 8 bits; a consumer-control report (ID 3, a 16-bit
# array) and a vendor collection with an output report (ID 4) and a 90-byte feature report (ID 5).
GAMING_16_DESCRIPTOR = [
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x85, 0x01,  # Mouse, Application, report ID 1
    0x09, 0x01, 0xA1, 0x00,
    0x05, 0x09, 0x19, 0x01, 0x29, 0x05, 0x15, 0x00, 0x25, 0x01, 0x95, 0x05, 0x75, 0x01, 0x81, 0x02,  # 5 buttons
    0x95, 0x03, 0x75, 0x01, 0x81, 0x01,  # 3 bits constant
    0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x16, 0x01, 0x80, 0x26, 0xFF, 0x7F, 0x75, 0x10, 0x95, 0x02,  # -32767..
    0x81, 0x06,  # X, Y: 16 bits x 2, relative
    0x09, 0x38, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06,  # wheel
    0x05, 0x0C, 0x0A, 0x38, 0x02, 0x95, 0x01, 0x81, 0x06,  # AC pan
    0xC0, 0xC0,
    0x05, 0x0C, 0x09, 0x01, 0xA1, 0x01, 0x85, 0x03,  # Consumer Control, report ID 3
    0x19, 0x00, 0x2A, 0xFF, 0x03, 0x15, 0x00, 0x26, 0xFF, 0x03, 0x75, 0x10, 0x95, 0x01, 0x81, 0x00,
    0xC0,
    0x06, 0x01, 0xFF, 0x09, 0x01, 0xA1, 0x01,  # vendor page 0xFF01, Application
    0x85, 0x04, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, 0x07, 0x09, 0x01, 0x91, 0x02,  # output ID 4
    0x85, 0x05, 0x95, 0x5A, 0x09, 0x02, 0xB1, 0x02,  # feature ID 5, 90 bytes
    0xC0,
]


def gaming_16_report(buttons, dx, dy, buttons_changed):
    return [[0x01, buttons & 0x1F] + le(dx, 2) + le(dy, 2) + [0, 0]]


# 250 Hz wireless mouse that sends its buttons apart from its motion, in the layout of the Xiaomi
# Mi Wireless Mouse's receiver (2717:003B; hid-tools' mouse tests describe it): report 1 holds 5
# buttons, 3 bits of padding, a wheel and AC pan (8 bits each, logical -127..127), report 2 X and Y
# (12 bits each, logical -2047..2047), and a consumer-control application holds media keys
# (report 3, one bit each, and 4 bits of padding). Written for this project from the HID Usage
# Tables (Generic Desktop 0x01, Button 0x09, Consumer 0x0C pages), not copied from any file.
SPLIT_DESCRIPTOR = [
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01,  # Generic Desktop, Mouse, Application
    0x85, 0x01, 0x09, 0x01, 0xA1, 0x00,  # report ID 1: Pointer, Physical
    0x05, 0x09, 0x19, 0x01, 0x29, 0x05, 0x15, 0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x05, 0x81, 0x02,  # 5 buttons
    0x75, 0x03, 0x95, 0x01, 0x81, 0x01,  # 3 bits constant
    0x05, 0x01, 0x09, 0x38, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06,  # wheel
    0x05, 0x0C, 0x0A, 0x38, 0x02, 0x81, 0x06,  # AC pan
    0xC0,
    0x85, 0x02, 0x05, 0x01, 0x09, 0x01, 0xA1, 0x00,  # report ID 2: Pointer, Physical
    0x09, 0x30, 0x09, 0x31, 0x16, 0x01, 0xF8, 0x26, 0xFF, 0x07, 0x75, 0x0C, 0x95, 0x02, 0x81, 0x06,  # X, Y
    0xC0, 0xC0,
    0x05, 0x0C, 0x09, 0x01, 0xA1, 0x01, 0x85, 0x03,  # Consumer Control, Application, report ID 3
    0x15, 0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x04,  # 4 keys, one bit each:
    0x09, 0xE9, 0x09, 0xEA, 0x09, 0xCD, 0x09, 0xB5, 0x81, 0x02,  # volume up, down, play/pause, next
    0x95, 0x04, 0x81, 0x01,  # 4 bits constant
    0xC0,
]


def split_reports(buttons, dx, dy, buttons_changed):
    reports = [[0x01, buttons & 0x1F, 0, 0]] if buttons_changed else []
    if (dx, dy) != (0, 0):
        reports.append([0x02] + le((dx & 0xFFF) | (dy & 0xFFF) << 12, 3))
    return reports


# (file, name, rate Hz, count size mm, logical limit of a delta, descriptor, packer, extra
# non-mouse reports as (time s, bytes)): the count sizes are those of 1210, 1600 and 3200 CPI.
MICE = [
    ("synthetic-125hz-8bit-boot.hid", "KF synthetic 125 Hz boot-like mouse (8-bit X/Y)", 125, 0.021, 127,
     BOOT_DESCRIPTOR, boot_report, []),
    ("synthetic-1khz-12bit-gaming.hid", "KF synthetic 1 kHz gaming mouse (12-bit X/Y)", 1000, 25.4 / 1600, 2047,
     GAMING_12_DESCRIPTOR, gaming_12_report,
     [(0.0105, [0x11, 0xFF, 0x00, 0x0D] + [0] * 16)]),  # a vendor notification: not a mouse report
    ("synthetic-8khz-16bit-gaming.hid", "KF synthetic 8 kHz gaming mouse (16-bit X/Y)", 8000, 25.4 / 3200, 32767,
     GAMING_16_DESCRIPTOR, gaming_16_report,
     [(0.0205, [0x03, 0xE9, 0x00])]),  # a volume-up key of the consumer-control report
    ("synthetic-250hz-split-buttons.hid", "KF synthetic 250 Hz mouse with buttons apart (Xiaomi layout)", 250,
     25.4 / 1000, 2047, SPLIT_DESCRIPTOR, split_reports,
     [(0.8502, [0x01, 0x00, 0x01, 0x00]),  # a wheel step: report 1 again, the buttons unchanged
      (1.1002, [0x03, 0x01]), (1.1202, [0x03, 0x00])]),  # volume up pressed and released
]


def events(rate_hz, count_mm, limit, pack):
    """(time s, report bytes, saturated) of every report the mouse sends (pack gives the reports of
    one poll: one for most mice, the buttons' and the motion's for one that sends them apart)."""
    out = []
    last_counts = (0, 0)
    last_buttons = 0
    polls = round(DURATION_S * rate_hz)
    for k in range(1, polls + 1):
        t = k / rate_hz
        counts = tuple(round(p / count_mm) for p in position_mm(t))
        dx, dy = (c - c0 for c, c0 in zip(counts, last_counts))
        buttons = buttons_at(t)
        last_counts = counts  # a clipped excess is lost, not carried
        if (dx, dy) == (0, 0) and buttons == last_buttons:
            continue
        buttons_changed = buttons != last_buttons
        last_buttons = buttons
        saturated = max(abs(dx), abs(dy)) >= limit
        dx, dy = (max(-limit, min(limit, d)) for d in (dx, dy))
        reports = pack(buttons, dx, dy, buttons_changed)
        for report in reports:  # the motion is in the last
            out.append((t, report, saturated and report is reports[-1]))
    return out


def hex_bytes(data):
    return " ".join(f"{b:02x}" for b in data)


def write_recording(file, name, rate_hz, count_mm, limit, descriptor, pack, extra):
    reports = events(rate_hz, count_mm, limit, pack)
    lines = [f"# {name}: synthetic, written by tests/data/hid/make_synthetic.py (see README.md)",
             f"# {rate_hz} Hz, count {count_mm:.7f} mm, deltas clipped at +-{limit} counts",
             f"R: {len(descriptor)} {hex_bytes(descriptor)}", f"N: {name}",
             "P: synthetic", "I: 3 0000 0000"]
    timed = [(t, data) for t, data, _ in reports] + extra
    for t, data in sorted(timed, key=lambda e: e[0]):
        lines.append(f"E: {t:.6f} {len(data)} {hex_bytes(data)}")
    (HERE / file).write_text("\n".join(lines) + "\n")
    saturated = sum(s for _, _, s in reports)
    print(f"{file}: {len(reports)} mouse reports ({saturated} saturated), {len(extra)} other")


def write_truth():
    lines = ["# t_s,x_mm,y_mm,buttons: the trajectory of the synthetic recordings (make_synthetic.py),"
             f" every {TRUTH_STEP_S * 1e3:g} ms"]
    for k in range(round(DURATION_S / TRUTH_STEP_S) + 1):
        t = k * TRUTH_STEP_S
        x, y = position_mm(t)
        lines.append(f"{t:.4f},{x:.9f},{y:.9f},{buttons_at(t)}")
    (HERE / "synthetic-trajectory.csv").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    for mouse in MICE:
        write_recording(*mouse)
    write_truth()
