#!/usr/bin/env python3
"""Designs the anti-alias filter of dsp/FrameFilter.hpp and prints its taps and response.

The force reaches the magnet as set-points held for a frame each (the board's zero-order hold).
ForceFramer takes, per frame, a weighted sum of the means of the last 16 quarter frames (a
symmetric FIR at four times the frame rate, 4 frames long). Its taps are the weighted least-squares
fit, the DC gain held at exactly 1, of:
- up to 0.3 times the frame rate: 1 / sinc(f / F), so that with the hold's droop the force's line
  keeps its height (the quarter-frame means' own sinc is part of the model);
- from 0.7 times the frame rate to the quarter frames' Nyquist: 0, weighted 4 times (what
  would fold back below 0.3 F);
- between the two: free.
Usage: /usr/bin/python3 dsp/design_frame_filter.py   (needs numpy)"""
import numpy as np

BINS_PER_FRAME = 4
FRAMES = 4
PASS_F, STOP_F, STOP_WEIGHT = 0.3, 0.7, 4.0
WEBER = 0.11  # a friction change people notice (Gueorguiev et al. 2017)


def response(taps, f):
    """The quarter-frame means and the FIR (before the frames are taken), at f in frame rates."""
    n = np.arange(len(taps)) - (len(taps) - 1) / 2
    return (np.cos(2 * np.pi * np.outer(f, n) / BINS_PER_FRAME) @ taps) * np.sinc(f / BINS_PER_FRAME)


def design():
    half = BINS_PER_FRAME * FRAMES // 2
    f = np.linspace(0, BINS_PER_FRAME / 2, 8000)
    offsets = np.arange(half) + 0.5  # the upper half's distances from the centre, in bins
    basis = 2 * np.cos(2 * np.pi * np.outer(f, offsets) / BINS_PER_FRAME) * np.sinc(f / BINS_PER_FRAME)[:, None]
    target = np.where(f <= PASS_F, 1 / np.sinc(f), 0.0)
    weight = np.where(f <= PASS_F, 1.0, np.where(f >= STOP_F, STOP_WEIGHT, 0.0))
    a, b = basis * weight[:, None], target * weight
    ones = 2 * np.ones((half, 1))  # the taps' sum, both halves
    kkt = np.block([[a.T @ a, ones], [ones.T, np.zeros((1, 1))]])
    upper = np.linalg.solve(kkt, np.concatenate([a.T @ b, [1.0]]))[:half]
    return np.concatenate([upper[::-1], upper])


def main():
    taps = design()
    f = np.linspace(0, BINS_PER_FRAME / 2, 16001)
    before = response(taps, f)
    held = before * np.sinc(f)
    within = f[np.argmax(np.abs(held - 1) > WEBER)]
    boxcar = np.sinc(f) ** 2
    print(f"taps (sum {taps.sum():.12f}):")
    print(",\n".join(f"    {t:.9f}" for t in taps[len(taps) // 2:]))
    print(f"held force within one Weber fraction up to {within:.3f} F "
          f"(the frame mean: {f[np.argmax(np.abs(boxcar - 1) > WEBER)]:.3f} F)")
    print(f"largest gain from 0.7 F up (what folds below 0.3 F): "
          f"{20 * np.log10(np.abs(before[f >= STOP_F]).max()):.1f} dB "
          f"(the frame mean: {20 * np.log10(np.abs(np.sinc(f[f >= STOP_F])).max()):.1f} dB)")
    print(f"group delay: {FRAMES / 2:.1f} frames from the frame's end (the frame mean: 0.5)")


if __name__ == "__main__":
    main()
