"""The friction patterns of FrictionPattern (dsp/*Pattern*, SpeedFriction) defined again in numpy,
from the positions a render read: the references the scene tests and the gallery compare with.

Every pattern is a level in [0, 1] (force = min + (max - min) * level) of the travel over the last
frame of n = round(rate * 1 ms) samples: from = x[i - n] (x[0] before the start), to = x[i]."""
import numpy as np

FRAME_S = 0.001
TEXTURE_COMPONENTS = 16
_MASK = (1 << 64) - 1


def _f32(*values):
    """Parameters as the UGen gets them: float inputs (0.2 is 0.20000000298...)."""
    return [float(np.float32(v)) for v in values]


def frame_samples(rate):
    return int(max(1, min(256, round(rate * FRAME_S))))


def travel(x, rate):
    """(from, to, direction, speed mm/s, frame period s) per sample of positions x (mm)."""
    x = np.asarray(x, dtype=np.float64)
    n = frame_samples(rate)
    start = np.concatenate([np.full(n, x[0]), x[:-n]]) if len(x) > n else np.full(len(x), x[0])
    d = x - start
    # The direction holds while the travel is 0 (+1 before the first move).
    sign = np.sign(d)
    idx = np.where(sign != 0, np.arange(len(d)), 0)
    np.maximum.accumulate(idx, out=idx)
    direction = np.where(sign[idx] != 0, sign[idx], 1.0)
    period = n / rate
    return start, x, direction, np.abs(d) / period, period


def fade(frequency_hz, period_s):
    """1 up to a quarter of the frame rate, 0 from half of it, a raised cosine between."""
    stop = 0.5 / period_s
    passed = 0.5 * stop
    f = np.asarray(frequency_hz, dtype=np.float64)
    g = 0.5 * (1 + np.cos(np.pi * (f - passed) / (stop - passed)))
    return np.where(f <= passed, 1.0, np.where(f >= stop, 0.0, g))


MAX_HARMONICS = 64
NEGLIGIBLE_FOLD = 1e-5


def sharp_harmonic(amplitude, power):
    """PatternTravel.cpp sharpHarmonic: the harmonic from which on (4 / pi) amplitude / k^power is at
    most NEGLIGIBLE_FOLD; 0 if amplitude already is."""
    level = 0.25 * np.pi * NEGLIGIBLE_FOLD
    return 0.0 if amplitude <= level else (amplitude / level) ** (1.0 / power)


def bump_sharp(omega):
    """RaisedCosineBump.cpp: the climb's and the height's kSharp, the larger."""
    def part(all_k, amplitude, power):
        return max(2 / omega, sharp_harmonic(amplitude, power)) if sharp_harmonic(all_k, 1) > 0 else 0.0
    return max(part(omega / np.pi, 4 / (3 * np.pi * omega), 2), part(omega / 2, 2 / (3 * np.pi * omega ** 2), 3))


def grating_sharp(duty, edge):
    """GratingPattern.cpp: |C_k| <= 1 / (pi k) and <= 1 / (pi^2 e k^2); 0 for duty 0 or 1."""
    if duty in (0.0, 1.0):
        return 0.0
    hard = sharp_harmonic(1 / np.pi, 1)
    return min(hard, sharp_harmonic(1 / (np.pi ** 2 * edge), 2)) if edge > 0 else hard


def detent_sharp(crest):
    """DetentPattern.cpp: |C_k| <= 1 / (pi k) from k = 1 / (pi c) on."""
    return max(1 / (np.pi * crest), sharp_harmonic(1 / np.pi, 1))


def spline_gain(r):
    """PatternTravel.hpp splineGain: the cubic B-spline, 1 at 0, 0 from |r| = 1 on."""
    a = np.minimum(np.abs(r), 1.0)
    b = 1 - a  # (products, not powers: numpy's power is the slow general one)
    return np.where(a <= 0.5, 1 - 6 * a * a * b, 2 * b * b * b)


def band_limited_series(boxed, mean, harmonics, u0, u1, speed, period_mm, period_s, k_sharp):
    """PatternTravel.cpp bandLimitedSeries: the box-filtered harmonics (coefficients harmonics[k - 1],
    fixed or per sample) weighted by spline_gain(k / k_cut), k_cut = min(k_stop, MAX_HARMONICS),
    k_stop = 500 Hz / (speed / period), up to k_full = max(MAX_HARMONICS, k_sharp); the closed-form
    boxed level from twice that on; a crossfade between."""
    f1 = np.asarray(speed, dtype=np.float64) / period_mm
    with np.errstate(divide="ignore", invalid="ignore"):
        k_stop = np.where(f1 > 0, 0.5 / period_s / np.where(f1 > 0, f1, 1), np.inf)
    return band_limited_series_to(k_stop, k_sharp, boxed, mean, harmonics, u0, u1)


def band_limited_series_to(k_stop, k_sharp, boxed, mean, harmonics, u0, u1):
    """PatternTravel.cpp bandLimitedSeriesTo: band_limited_series with k_stop given (inf: boxed).
    Harmonic k's e^(i k phase) and sin(k x) are stepped from harmonic k - 1's by one complex product
    each (the model's cost, run for every texture scene twice: 15 of test_patterns_nrt's 20 s with
    an exp and a sin per harmonic); the harmonics at or above every sample's k_cut, whose spline
    gain is 0, are not summed."""
    k_full = max(MAX_HARMONICS, k_sharp)
    between = np.clip(k_stop, k_full, 2 * k_full)
    h = 0.5 * (1 - np.cos(np.pi * (between - k_full) / k_full))
    k_cut = np.minimum(k_stop, MAX_HARMONICS)
    mid, length = 0.5 * (u0 + u1), np.abs(u1 - u0)
    series = np.full(np.shape(boxed), float(mean))
    summed = k_cut[h < 1] if np.ndim(h) else (k_cut if h < 1 else 0)
    k_last = min(MAX_HARMONICS - 1, int(np.ceil(np.max(summed, initial=0))))
    step_phase = np.exp(2j * np.pi * (mid - np.floor(mid)))
    step_x = np.exp(1j * np.pi * length)
    turn_phase, turn_x = np.ones_like(step_phase), np.ones_like(step_x)
    small = np.pi * length < 1e-9
    x_per_k = np.where(small, 1.0, np.pi * length)
    for k in range(1, k_last + 1):
        turn_phase = turn_phase * step_phase
        turn_x = turn_x * step_x
        sinc = np.where(small, 1.0, turn_x.imag / (k * x_per_k))
        with np.errstate(divide="ignore"):
            gain = spline_gain(k / k_cut)  # 0 from k = k_cut on
        series += gain * 2 * np.real(harmonics[k - 1] * turn_phase) * sinc
    return np.where(h >= 1, boxed, h * boxed + (1 - h) * series)


def grating_harmonics(duty, edge):
    """GratingPattern.hpp: C_k = e^(-i pi k (d + e)) sin(pi k d) / (pi k) sinc(pi k e)."""
    k = np.arange(1, MAX_HARMONICS + 1)
    return np.exp(-1j * np.pi * k * (duty + edge)) * np.sin(np.pi * k * duty) / (np.pi * k) * np.sinc(k * edge)


def height_harmonics(omega):
    """RaisedCosineBump.hpp: the height's C_k = E(-a) / 2 - (E(b - a) + E(-b - a)) / 4 over [0, omega)."""
    k = np.arange(1, MAX_HARMONICS + 1)
    a, b = 2 * np.pi * k, 2 * np.pi / omega

    def e(q):
        return omega * np.exp(0.5j * q * omega) * np.sinc(q * omega / (2 * np.pi))

    return e(-a) / 2 - (e(b - a) + e(-b - a)) / 4


def bump_harmonics(omega, valleys):
    """HeightSlopePattern.hpp: (climbing moving +1, moving -1)."""
    k = np.arange(1, MAX_HARMONICS + 1)
    a, b, half = 2 * np.pi * k, 2 * np.pi / omega, omega / 2

    def e(q):
        return half * np.exp(0.5j * q * half) * np.sinc(q * half / (2 * np.pi))

    first = (e(b - a) - e(-b - a)) / 2j
    second = np.exp(-1j * a * omega) * np.conj(first)
    return (second, first) if valleys else (first, second)


def detent_harmonics(crest):
    """DetentPattern.hpp: C_k = i e^(-i a c) / a + (e^(-i a c) - 1) / (a^2 c), a = 2 pi k."""
    a = 2 * np.pi * np.arange(1, MAX_HARMONICS + 1)
    e = np.exp(-1j * a * crest)
    return 1j * e / a + (e - 1) / (a * a * crest)


def _periodic_mean(u0, u1, per_period, partial, point):
    lo, hi = np.minimum(u0, u1), np.maximum(u0, u1)
    length = hi - lo
    w0, w1 = np.floor(lo), np.floor(hi)
    boxed = ((w1 - w0) * per_period + partial(hi - w1) - partial(lo - w0)) / np.where(length > 0, length, 1)
    return np.where(length >= 1e-9, boxed, point(hi - np.floor(hi)))


def grating(x, rate, period, duty, edge, antialias=True):
    start, to, _, speed, t = travel(x, rate)
    period, duty, edge = _f32(period, duty, edge)
    d = np.clip(duty, 0, 1)
    e = np.clip(edge / period, 0, min(d, 1 - d))

    def at(f):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(f < e, f / e, np.where(f < d, 1.0, np.where(f < d + e, 1 - (f - d) / e, 0.0)))

    def partial(f):
        with np.errstate(divide="ignore", invalid="ignore"):
            g = f - d
            return np.where(f < e, f * f / (2 * e), np.where(f < d, f - e / 2, np.where(
                f < d + e, d - e / 2 + g - g * g / (2 * e), d)))

    u0, u1 = start / period, to / period
    if not antialias:
        return at(u1 - np.floor(u1))
    boxed = _periodic_mean(u0, u1, d, partial, at)
    return np.clip(band_limited_series(boxed, d, grating_harmonics(d, e), u0, u1, speed, period, t,
                                       grating_sharp(d, e)), 0, 1)


def bumps(x, rate, period, width, valleys=False, antialias=True):
    start, to, direction, speed, t = travel(x, rate)
    period, width = _f32(period, width)
    omega = np.clip(width / period, 1e-6, 1)
    sgn = -1.0 if valleys else 1.0

    def bump(f):
        return np.where(f < omega, 0.5 * (1 - np.cos(2 * np.pi * f / omega)), 0.0)

    def at(f):
        return np.where(f < omega, np.maximum(0, direction * sgn * np.sin(2 * np.pi * f / omega)), 0.0)

    def climb(f):
        first = (direction > 0) != valleys
        half = omega / 2
        up = np.where(f < half, bump(f), 1.0)
        down = np.where(f < half, 0.0, np.where(f < omega, 1 - bump(f), 1.0))
        return np.where(first, up, down)

    u0, u1 = start / period, to / period
    if not antialias:
        return at(u1 - np.floor(u1))
    scale = omega / np.pi
    boxed = _periodic_mean(u0, u1, scale, lambda f: scale * climb(f), at)
    up, down = bump_harmonics(omega, valleys)
    harmonics = np.where(direction[None, :] > 0, up[:, None], down[:, None])
    return np.clip(band_limited_series(boxed, scale, harmonics, u0, u1, speed, period, t, bump_sharp(omega)),
                   0, 1)


def detents(x, rate, spacing, crest, antialias=True):
    start, to, direction, speed, t = travel(x, rate)
    spacing, crest = _f32(spacing, crest)
    c = np.clip(crest, 1e-6, 1)
    u0, u1 = direction * start / spacing, direction * to / spacing

    def along(g):
        return np.where(g < c, g / c, 0.0)

    if not antialias:
        return along(u1 - np.floor(u1))
    boxed = _periodic_mean(u0, u1, c / 2, lambda g: np.where(g < c, g * g / (2 * c), c / 2), along)
    return np.clip(band_limited_series(boxed, c / 2, detent_harmonics(c), u0, u1, speed, spacing, t,
                                       detent_sharp(c)), 0, 1)


def _splitmix(state):
    state = (state + 0x9E3779B97F4A7C15) & _MASK
    z = state
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    return state, (z ^ (z >> 31)) & _MASK


def texture_components(lo, hi, seed):
    lo, hi = _f32(min(lo, hi), max(lo, hi))
    state, freqs, phases = int(seed) & _MASK, [], []
    for _ in range(TEXTURE_COMPONENTS):
        state, a = _splitmix(state)
        state, b = _splitmix(state)
        freqs.append(lo + (hi - lo) * ((a >> 11) * 2.0 ** -53))
        phases.append(2 * np.pi * ((b >> 11) * 2.0 ** -53))
    return np.array(freqs), np.array(phases)


def texture(x, rate, lo, hi, seed, antialias=True):
    start, to, _, speed, t = travel(x, rate)
    freqs, phases = texture_components(lo, hi, seed)
    amplitude = 1 / (6 * np.sqrt(TEXTURE_COMPONENTS / 2))
    total = np.zeros(len(to))
    for f, phi in zip(freqs, phases):
        w = 2 * np.pi * f
        if not antialias:
            total += np.sin(w * to + phi)
            continue
        half = 0.5 * w * (to - start)
        with np.errstate(divide="ignore", invalid="ignore"):
            sinc = np.where(np.abs(half) < 1e-8, 1.0, np.sin(half) / half)
        total += fade(speed * f, t) * sinc * np.sin(w * 0.5 * (start + to) + phi)
    return np.clip(0.5 + amplitude * total, 0, 1)


def viscous(x, rate, full_speed):
    return np.clip(travel(x, rate)[3] / _f32(full_speed)[0], 0, 1)


def stick_slip(x, rate, slip_speed, stick_speed):
    speed = travel(x, rate)[3]
    slip_speed, stick_speed = _f32(slip_speed, stick_speed)
    stick = min(stick_speed, slip_speed)
    out, sliding = np.empty(len(speed)), False
    for i, v in enumerate(speed):
        if not sliding and v > slip_speed:
            sliding = True
        elif sliding and v < stick:
            sliding = False
        out[i] = 0.0 if sliding else 1.0
    return out


def slope(x, height, rate, full_slope):
    start, to, _, _, _ = travel(x, rate)
    full_slope = _f32(full_slope)[0]
    h = np.asarray(height, dtype=np.float64)
    n = frame_samples(rate)
    h0 = np.concatenate([np.full(n, h[0]), h[:-n]])
    moved = np.abs(to - start)
    out, held = np.empty(len(h)), 0.0
    for i in range(len(h)):
        if moved[i] >= 1e-4:
            held = min(max((h[i] - h0[i]) / moved[i] / full_slope, 0.0), 1.0)
        out[i] = held
    return out


def _held(values, valid, before):
    """values where valid, else the last valid one (before: before the first)."""
    idx = np.where(valid, np.arange(len(values)), -1)
    np.maximum.accumulate(idx, out=idx)
    return np.where(idx >= 0, values[np.maximum(idx, 0)], before)


def bumps2d(x, y, rate, spacing_x, spacing_y, width, antialias=True):
    """GridBumpsPattern.hpp: the 2D grid of bumps h = b(x) b(y), the climb counted per axis,
    (|ux| (pi / wx) c(x) b(y) + |uy| b(x) (pi / wy) c(y)) / (pi / min(wx, wy)), each one-axis
    factor its mean over that axis's travel, band-limited to its share of the frames' Nyquist
    frequency (Kx fx + Ky fy = 500 Hz); raw: the rule at the point. The direction (ux, uy and each
    axis's sign) is the last travel's, held while still (none before the first: 0)."""
    spacing_x, spacing_y, width = _f32(spacing_x, spacing_y, width)
    x0, x1, _, _, t = travel(x, rate)
    y0, y1, _, _, _ = travel(y, rate)
    dx, dy = x1 - x0, y1 - y0
    moved = np.hypot(dx, dy)
    with np.errstate(divide="ignore", invalid="ignore"):
        ux = _held(np.abs(dx) / moved, moved > 0, 0.0)
        uy = _held(np.abs(dy) / moved, moved > 0, 0.0)
    sx, sy = _held(np.sign(dx), dx != 0, 1.0), _held(np.sign(dy), dy != 0, 1.0)
    rx, ry = np.sqrt(np.abs(dx) / t / spacing_x), np.sqrt(np.abs(dy) / t / spacing_y)

    def axis(u0, u1, omega, s, k_stop):
        half = omega / 2

        def bump(f):
            return np.where(f < omega, 0.5 * (1 - np.cos(2 * np.pi * f / omega)), 0.0)

        def at(f):
            return np.where(f < omega, np.maximum(0, s * np.sin(2 * np.pi * f / omega)), 0.0)

        def climb(f):
            up = np.where(f < half, bump(f), 1.0)
            down = np.where(f < half, 0.0, np.where(f < omega, 1 - bump(f), 1.0))
            return np.where(s > 0, up, down)

        def height_to(f):
            return np.where(f < omega, f / 2 - omega / (4 * np.pi) * np.sin(2 * np.pi * f / omega), half)

        if not antialias:
            f = u1 - np.floor(u1)
            return at(f), bump(f)
        scale = omega / np.pi
        climbed = _periodic_mean(u0, u1, scale, lambda f: scale * climb(f), at)
        height = _periodic_mean(u0, u1, half, height_to, bump)
        up, down = bump_harmonics(omega, False)
        harmonics = np.where(s[None, :] > 0, up[:, None], down[:, None])
        sharp = bump_sharp(omega)
        return (band_limited_series_to(k_stop, sharp, climbed, scale, harmonics, u0, u1),
                band_limited_series_to(k_stop, sharp, height, half, height_harmonics(omega), u0, u1))

    ox, oy = min(max(width / spacing_x, 1e-6), 1.0), min(max(width / spacing_y, 1e-6), 1.0)
    wx, wy = ox * spacing_x, oy * spacing_y
    with np.errstate(divide="ignore", invalid="ignore"):
        nyquist = 0.5 / t
        cx, bx = axis(x0 / spacing_x, x1 / spacing_x, ox, sx, nyquist / (rx * (rx + ry)))
        cy, by = axis(y0 / spacing_y, y1 / spacing_y, oy, sy, nyquist / (ry * (rx + ry)))
        g = (ux * np.pi / wx * cx * by + uy * np.pi / wy * bx * cy) / (np.pi / min(wx, wy))
    g = np.clip(g, 0.0, 1.0)
    out, held = np.empty(len(g)), 0.0
    for i in range(len(g)):
        if np.isfinite(g[i]):
            held = g[i]
        out[i] = held
    return out


TEXTURE_2D_COMPONENTS = 32


def texture2d_components(lo, hi, seed):
    """(fx, fy, phase) per plane wave: |f| in [lo, hi], then its angle, then its phase."""
    lo, hi = _f32(min(lo, hi), max(lo, hi))
    state, waves = int(seed) & _MASK, []
    for _ in range(TEXTURE_2D_COMPONENTS):
        draws = []
        for _ in range(3):
            state, z = _splitmix(state)
            draws.append((z >> 11) * 2.0 ** -53)
        magnitude, angle = lo + (hi - lo) * draws[0], 2 * np.pi * draws[1]
        waves.append((magnitude * np.cos(angle), magnitude * np.sin(angle), 2 * np.pi * draws[2]))
    return np.array(waves)


def texture2d(x, y, rate, lo, hi, seed, antialias=True):
    """The 2D texture: each plane wave's mean over the frame's straight travel in (x, y), faded on
    its own temporal frequency |f.v| (antialias False: the sum at the current position)."""
    x0, x1, _, _, t = travel(x, rate)
    y0, y1, _, _, _ = travel(y, rate)
    amplitude = 1 / (6 * np.sqrt(TEXTURE_2D_COMPONENTS / 2))
    total = np.zeros(len(x1))
    for fx, fy, phi in texture2d_components(lo, hi, seed):
        if not antialias:
            total += np.sin(2 * np.pi * (fx * x1 + fy * y1) + phi)
            continue
        half = np.pi * (fx * (x1 - x0) + fy * (y1 - y0))
        with np.errstate(divide="ignore", invalid="ignore"):
            sinc = np.where(np.abs(half) < 1e-8, 1.0, np.sin(half) / half)
        hz = np.abs(fx * (x1 - x0) + fy * (y1 - y0)) / t
        total += fade(hz, t) * sinc * np.sin(np.pi * (fx * (x0 + x1) + fy * (y0 + y1)) + phi)
    return np.clip(0.5 + amplitude * total, 0, 1)
