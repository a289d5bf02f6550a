// Reads a 1D signal laid out on the surface: position (mm) -> buffer index -> interpolated
// sample. The signal is taken as zero outside its frames, so the interpolators fade it in and
// out at the borders instead of wrapping, and the output is exactly 0 once the index is a
// whole sample or more outside [0, frames - 1].
#pragma once

#include <cmath>
#include <cstdint>

namespace kf {

// The same codes as BufRd's interpolation argument.
enum class Interpolation : int { None = 1, Linear = 2, Cubic = 4 };

// Any code other than 1 or 2 reads cubic, as BufRd does.
Interpolation interpolationFromCode(int code);

// index = (position - origin) * samplesPerMm, in double so that the index of a position far
// from the origin is exact where a float phase is not. Non-finite results map to NaN, which
// readSpatial() turns into silence.
inline double spatialIndex(double positionMm, double originMm, double samplesPerMm) {
  return (positionMm - originMm) * samplesPerMm;
}

// One channel of an interleaved buffer of `frames` frames and `channels` channels.
struct SignalView {
  const float* data = nullptr;
  int64_t frames = 0;
  int channels = 1;
};

// The 4-point Hermite (Catmull-Rom) kernel BufRd's cubic uses, so results compare directly:
// interpolates between y1 (frac 0) and y2 (frac 1).
inline float cubicHermite(float frac, float y0, float y1, float y2, float y3) {
  const float c1 = 0.5f * (y2 - y0);
  const float c2 = y0 - 2.5f * y1 + 2.f * y2 - 0.5f * y3;
  const float c3 = 0.5f * (y3 - y0) + 1.5f * (y1 - y2);
  return ((c3 * frac + c2) * frac + c1) * frac + y1;
}

namespace detail {

// Sample k of the zero-padded signal.
inline float sampleAt(const SignalView& s, int channel, int64_t k) {
  if (k < 0 || k >= s.frames) return 0.f;
  return s.data[k * s.channels + channel];
}

// floor(x) for x > -1 (callers have range-checked x), without a libm call: the default x86-64
// target has no SSE4.1 round, so std::floor(double) is a call per sample.
inline int64_t floorAboveMinusOne(double x) {
  const int64_t t = static_cast<int64_t>(x);  // truncates toward zero
  return t - (static_cast<double>(t) > x);
}

}  // namespace detail

// Reads channel `channel` at fractional `index`. Returns 0 for a NaN/Inf index, an empty
// signal, or an index at or beyond one sample outside the signal. Inline: it runs per sample.
// The UGen reads whole blocks with readSpatialBlock(), which gives the same values.
inline float readSpatial(const SignalView& s, int channel, double index, Interpolation interpolation) {
  if (s.data == nullptr || s.frames <= 0) return 0.f;
  // Outside (-1, frames) every tap is a padded zero; this also rejects NaN and +-Inf, and keeps
  // the integer conversion below in range.
  if (!(index > -1.0 && index < static_cast<double>(s.frames))) return 0.f;

  const int64_t i = detail::floorAboveMinusOne(index);
  const float frac = static_cast<float>(index - static_cast<double>(i));
  const float* p = s.data + channel;
  const int64_t stride = s.channels;

  switch (interpolation) {
    case Interpolation::None:
      return detail::sampleAt(s, channel, i);
    case Interpolation::Linear: {
      const float y1 = detail::sampleAt(s, channel, i);
      const float y2 = detail::sampleAt(s, channel, i + 1);
      return y1 + frac * (y2 - y1);
    }
    case Interpolation::Cubic:
    default:
      if (i >= 1 && i + 2 < s.frames) {  // all four taps inside: no padding checks
        const float* q = p + (i - 1) * stride;
        return cubicHermite(frac, q[0], q[stride], q[2 * stride], q[3 * stride]);
      }
      return cubicHermite(frac, detail::sampleAt(s, channel, i - 1), detail::sampleAt(s, channel, i),
                          detail::sampleAt(s, channel, i + 1), detail::sampleAt(s, channel, i + 2));
  }
}

// A block of positions read at once, every channel of the signal: out[c][i] is
// readSpatial(s, c, spatialIndex(positionMm[i * positionStride], originMm, samplesPerMm),
// interpolation), bit for bit. positionStride is 1 for an audio-rate position, 0 for one
// position held over the block. Every position of a piece is read before its outputs are
// written, so an output may share memory with positionMm. out holds s.channels pointers.
//
// Two passes per piece of up to 64 samples: the indices in double -> whole part and float
// fraction (branch-free, vectorized), then the taps, with no padding checks where the whole
// piece lies inside the signal (one check per piece, not per sample).
void readSpatialBlock(const SignalView& s, const float* positionMm, int positionStride, double originMm,
                      double samplesPerMm, Interpolation interpolation, float* const* out, int numSamples);

}  // namespace kf
