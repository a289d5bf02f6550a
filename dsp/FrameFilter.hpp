// How ForceFramer turns audio-rate force into one value per frame.
//
// kMean, the paper's: each frame is the exact mean of its own samples. Its group delay is half a
// frame, the least any filter has; it passes what the frames cannot carry (a line at 0.7 times the
// frame rate comes out at -8.7 dB, folded below 0.3 F) and, with the board's hold, keeps a line
// within one Weber fraction (0.11) of its height only up to 0.187 F.
//
// kAntiAlias: each frame is a symmetric FIR over the means of its last 16 quarter frames (4 frames),
// designed by dsp/design_frame_filter.py: the hold's droop made up to 0.3 F (a line within one
// Weber fraction up to 0.304 F), -30.6 dB from 0.7 F up. Its cost: a group delay of 2 frames from
// the frame's end instead of half a frame (1.5 frames more: 0.19 ms at 8 kHz, 1.5 ms at 1 kHz,
// which is why the paper's 1 kHz keeps the mean), and a step overshoots by 10.3 % of its height
// for about two frames before it settles (clamped to the force range like every frame).
#pragma once

namespace kf {

enum class FrameFilter { kMean, kAntiAlias };

namespace frame_filter {

constexpr int kBinsPerFrame = 4;
constexpr int kTaps = 16;
// The upper half of the symmetric taps, from the centre out (the design script prints them).
constexpr double kHalfTaps[kTaps / 2] = {0.255714860,  0.200707009,  0.114687424,  0.031814062,
                                         -0.021504655, -0.038503137, -0.029582753, -0.013332810};

// Tap k of 16, k = 0 the oldest quarter frame's.
constexpr double tap(int k) { return kHalfTaps[k < kTaps / 2 ? kTaps / 2 - 1 - k : k - kTaps / 2]; }

// The filter a device's frame rate gets: the paper's mean at 1 kHz and below, where 1.5 frames
// more would break the 1 ms budget; the anti-alias filter at the faster rates (8 kHz: 0.19 ms).
inline FrameFilter forPeriod(double framePeriodS) {
  return framePeriodS < 0.999e-3 ? FrameFilter::kAntiAlias : FrameFilter::kMean;
}

}  // namespace frame_filter
}  // namespace kf
