#include "SpatialReader.hpp"

#include <algorithm>
#include <climits>

#include "CorePath.hpp"

#if KF_CORE_AVX2
#include <immintrin.h>
#endif

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

namespace kf {

Interpolation interpolationFromCode(int code) {
  if (code == 1) return Interpolation::None;
  if (code == 2) return Interpolation::Linear;
  return Interpolation::Cubic;
}

namespace {

constexpr int kPiece = 64;  // samples per two-pass piece: the arrays stay in L1
// Whole part given to samples outside (-1, frames): every tap of every mode is a padded zero
// there (cubic reads -4 .. -1), and with fraction 0 the kernels give exactly 0.
constexpr int32_t kOutside = -3;

// Taps left and right of the whole part, per mode.
template <Interpolation I>
constexpr int kTapsLeft = I == Interpolation::Cubic ? 1 : 0;
template <Interpolation I>
constexpr int kTapsRight = I == Interpolation::Cubic ? 2 : (I == Interpolation::Linear ? 1 : 0);

struct Piece {
  int32_t whole[kPiece];
  float frac[kPiece];
};

// One index -> (whole, frac), branch-free; the same arithmetic as readSpatial().
inline void split(double x, double framesD, int32_t& whole, float& frac) {
  const bool inside = x > -1.0 && x < framesD;  // false for NaN and +-Inf
  x = inside ? x : double(kOutside);
  double t = static_cast<double>(static_cast<int32_t>(x));  // truncation; |x| < 2^31 here
  t -= t > x ? 1.0 : 0.0;                                   // floor, as x > -1 or x == -3
  whole = static_cast<int32_t>(t);
  frac = static_cast<float>(x - t);
}

// Pass 1. Returns whether every tap of the piece lies inside the signal.
template <Interpolation I>
bool splitIndices(const float* positionMm, int positionStride, double originMm, double samplesPerMm, int64_t frames,
                  int n, Piece& p) {
  const double framesD = static_cast<double>(frames);
  if (positionStride == 0) {
    int32_t w;
    float f;
    split((static_cast<double>(positionMm[0]) - originMm) * samplesPerMm, framesD, w, f);
    std::fill_n(p.whole, n, w);
    std::fill_n(p.frac, n, f);
    return w >= kTapsLeft<I> && w + kTapsRight<I> < frames;
  }
  // Every tap inside: kTapsLeft <= whole <= frames - 1 - kTapsRight (outside samples have
  // whole == kOutside, below that). An OR over the piece, which vectorizes.
  const int32_t lastWhole = static_cast<int32_t>(frames - 1 - kTapsRight<I>);
  int32_t border = 0;
  int i = 0;
#if defined(__SSE2__)
  {
    // Four at a time, in two double pairs. floor by the magic number: adding 1.5 * 2^52 rounds
    // x to the nearest integer (|x| < 2^31 here), which is then in the low 32 bits of the sum;
    // one less where that is above x. The same values as split(), without the int conversions.
    const __m128d origin = _mm_set1_pd(originMm), spm = _mm_set1_pd(samplesPerMm);
    const __m128d minusOne = _mm_set1_pd(-1.0), end = _mm_set1_pd(framesD), outside = _mm_set1_pd(kOutside);
    const __m128d magic = _mm_set1_pd(6755399441055744.0), one = _mm_set1_pd(1.0);
    const __m128i low = _mm_set1_epi32(kTapsLeft<I>), high = _mm_set1_epi32(lastWhole);
    __m128i anyBorder = _mm_setzero_si128();
    auto pair = [&](const float* pos, __m128i& whole, __m128& frac) {
      __m128d x = _mm_mul_pd(
          _mm_sub_pd(_mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pos)))), origin),
          spm);
      const __m128d inside = _mm_and_pd(_mm_cmpgt_pd(x, minusOne), _mm_cmplt_pd(x, end));
      x = _mm_or_pd(_mm_and_pd(inside, x), _mm_andnot_pd(inside, outside));
      const __m128d r = _mm_add_pd(x, magic);
      const __m128d rounded = _mm_sub_pd(r, magic);
      const __m128d above = _mm_cmpgt_pd(rounded, x);
      const __m128d floorX = _mm_sub_pd(rounded, _mm_and_pd(above, one));
      frac = _mm_cvtpd_ps(_mm_sub_pd(x, floorX));  // in the low two lanes
      // low 32 bits of r, plus the mask (-1) where rounded > x, in the low two int lanes
      whole =
          _mm_add_epi32(_mm_shuffle_epi32(_mm_castpd_si128(r), 0x08), _mm_shuffle_epi32(_mm_castpd_si128(above), 0x08));
    };
    for (; i + 4 <= n; i += 4) {
      __m128i w0, w1;
      __m128 f0, f1;
      pair(positionMm + i, w0, f0);
      pair(positionMm + i + 2, w1, f1);
      const __m128i whole = _mm_unpacklo_epi64(w0, w1);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(p.whole + i), whole);
      _mm_storeu_ps(p.frac + i, _mm_movelh_ps(f0, f1));
      anyBorder = _mm_or_si128(anyBorder, _mm_or_si128(_mm_cmpgt_epi32(low, whole), _mm_cmpgt_epi32(whole, high)));
    }
    border = _mm_movemask_epi8(anyBorder);
  }
#endif
  for (; i < n; ++i) {
    split((static_cast<double>(positionMm[i]) - originMm) * samplesPerMm, framesD, p.whole[i], p.frac[i]);
    border |= (p.whole[i] < kTapsLeft<I>) | (p.whole[i] > lastWhole);
  }
  return border == 0;
}

#if KF_CORE_AVX2
struct IndexConstants {
  __m256d origin, spm, minusOne, end;
};

// Four indices -> whole parts and fractions, as split() computes them; floor by vroundpd (AVX),
// exact. Without Outside (none), indices outside (-1, frames) keep their own floor instead of
// kOutside: none's padded read gives 0 for any whole part outside the signal, which is where
// they all are, and one beyond int32 (also NaN, Inf) converts to INT32_MIN, outside too.
template <bool Outside>
__attribute__((target("avx2,fma"), always_inline)) inline void splitFour(const IndexConstants& c, const float* pos,
                                                                         __m128i& whole, __m128& frac) {
  __m256d x = _mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(pos)), c.origin), c.spm);
  if constexpr (Outside) {
    const __m256d inside = _mm256_and_pd(_mm256_cmp_pd(x, c.minusOne, _CMP_GT_OQ), _mm256_cmp_pd(x, c.end, _CMP_LT_OQ));
    x = _mm256_blendv_pd(_mm256_set1_pd(kOutside), x, inside);
  }
  const __m256d floorX = _mm256_round_pd(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  if constexpr (Outside) frac = _mm256_cvtpd_ps(_mm256_sub_pd(x, floorX));
  whole = _mm256_cvttpd_epi32(floorX);
}

// Pass 1 on the AVX2 path: splitIndices' operations four doubles wide (no FMA: the index is
// (position - origin) * samplesPerMm rounded twice, as readSpatial() computes it). The whole part
// is the floor converted by truncation, exact as the floor is an integer below 2^31.
// With Gather (mono none), pass 2 is done here too: each sample gathered at its whole part
// clamped into the signal, right away. That is the output wherever the piece turns out to lie
// inside; a piece that does not is read again by readPadded (the clamp only keeps the gathers
// in memory).
template <Interpolation I, bool Gather = false>
__attribute__((target("avx2,fma"))) bool splitIndicesAvx2(const float* positionMm, int positionStride, double originMm,
                                                          double samplesPerMm, int64_t frames, int n, Piece& p,
                                                          const float* data = nullptr, float* out = nullptr) {
  static_assert(!Gather || I == Interpolation::None, "the gather reads one tap");
  if (positionStride == 0) {
    const bool inside = splitIndices<I>(positionMm, 0, originMm, samplesPerMm, frames, n, p);
    if constexpr (Gather)
      if (inside) std::fill_n(out, n, data[p.whole[0]]);
    return inside;
  }
  const int32_t lastWhole = static_cast<int32_t>(frames - 1 - kTapsRight<I>);
  const IndexConstants c{_mm256_set1_pd(originMm), _mm256_set1_pd(samplesPerMm), _mm256_set1_pd(-1.0),
                         _mm256_set1_pd(static_cast<double>(frames))};
  const __m256i low = _mm256_set1_epi32(kTapsLeft<I>), high = _mm256_set1_epi32(lastWhole);
  __m256i anyBorder = _mm256_setzero_si256();
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    __m128i w0, w1;
    __m128 f0{}, f1{};  // none: not computed
    splitFour<I != Interpolation::None>(c, positionMm + i, w0, f0);
    splitFour<I != Interpolation::None>(c, positionMm + i + 4, w1, f1);
    const __m256i whole = _mm256_set_m128i(w1, w0);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(p.whole + i), whole);
    if constexpr (Gather)
      _mm256_storeu_ps(out + i, _mm256_i32gather_ps(data, _mm256_min_epi32(_mm256_max_epi32(whole, low), high), 4));
    if constexpr (I != Interpolation::None) _mm256_storeu_ps(p.frac + i, _mm256_set_m128(f1, f0));  // none: unread
    anyBorder =
        _mm256_or_si256(anyBorder, _mm256_or_si256(_mm256_cmpgt_epi32(low, whole), _mm256_cmpgt_epi32(whole, high)));
  }
  int32_t border = !_mm256_testz_si256(anyBorder, anyBorder);
  for (; i < n; ++i) {
    split((static_cast<double>(positionMm[i]) - originMm) * samplesPerMm, static_cast<double>(frames), p.whole[i],
          p.frac[i]);
    border |= (p.whole[i] < kTapsLeft<I>) | (p.whole[i] > lastWhole);
    if constexpr (Gather) out[i] = data[std::clamp(p.whole[i], kTapsLeft<I>, lastWhole)];
  }
  return border == 0;
}
#endif

template <Interpolation I>
inline float kernel(const float* q, int64_t stride, float frac) {
  if constexpr (I == Interpolation::None) {
    return q[0];
  } else if constexpr (I == Interpolation::Linear) {
    const float y1 = q[0], y2 = q[stride];
    return y1 + frac * (y2 - y1);
  } else {
    return cubicHermite(frac, q[-stride], q[0], q[stride], q[2 * stride]);
  }
}

// Pass 2 where every tap is inside: no checks. Stride is 1 for a mono signal (known at compile
// time there), the channel count otherwise.
template <Interpolation I, int FixedStride>
void readInside(const float* channelData, int64_t stride, const Piece& p, float* out, int n) {
  if constexpr (FixedStride > 0) stride = FixedStride;
#if defined(__SSE2__)
  if constexpr (I == Interpolation::Cubic && FixedStride == 1) {
    // Mono cubic: the four taps of a sample are adjacent, so one unaligned load each and a 4x4
    // transpose gather four samples' taps into y0..y3; the kernel then runs four wide, with the
    // same operations in the same order as cubicHermite(), so the results are identical.
    int i = 0;
    for (; i + 4 <= n; i += 4) {
      __m128 y0 = _mm_loadu_ps(channelData + p.whole[i] - 1);
      __m128 y1 = _mm_loadu_ps(channelData + p.whole[i + 1] - 1);
      __m128 y2 = _mm_loadu_ps(channelData + p.whole[i + 2] - 1);
      __m128 y3 = _mm_loadu_ps(channelData + p.whole[i + 3] - 1);
      _MM_TRANSPOSE4_PS(y0, y1, y2, y3);
      const __m128 frac = _mm_loadu_ps(p.frac + i);
      const __m128 half = _mm_set1_ps(0.5f);
      const __m128 c1 = _mm_mul_ps(half, _mm_sub_ps(y2, y0));
      const __m128 c2 =
          _mm_sub_ps(_mm_add_ps(_mm_sub_ps(y0, _mm_mul_ps(_mm_set1_ps(2.5f), y1)), _mm_mul_ps(_mm_set1_ps(2.f), y2)),
                     _mm_mul_ps(half, y3));
      const __m128 c3 =
          _mm_add_ps(_mm_mul_ps(half, _mm_sub_ps(y3, y0)), _mm_mul_ps(_mm_set1_ps(1.5f), _mm_sub_ps(y1, y2)));
      __m128 r = _mm_add_ps(_mm_mul_ps(c3, frac), c2);
      r = _mm_add_ps(_mm_mul_ps(r, frac), c1);
      r = _mm_add_ps(_mm_mul_ps(r, frac), y1);
      _mm_storeu_ps(out + i, r);
    }
    for (; i < n; ++i) out[i] = kernel<I>(channelData + p.whole[i], 1, p.frac[i]);
    return;
  }
#endif
  for (int i = 0; i < n; ++i)
    out[i] = kernel<I>(channelData + static_cast<int64_t>(p.whole[i]) * stride, stride, p.frac[i]);
}

// Pass 2 of a piece that touches a border or the outside: padded taps per sample.
template <Interpolation I>
void readPadded(const SignalView& s, int channel, const Piece& p, float* out, int n) {
  const float* data = s.data + channel;
  const int64_t stride = s.channels;
  for (int i = 0; i < n; ++i) {
    const int64_t k = p.whole[i];
    if (k >= kTapsLeft<I> && k + kTapsRight<I> < s.frames) {
      out[i] = kernel<I>(data + k * stride, stride, p.frac[i]);
      continue;
    }
    const float f = p.frac[i];
    if constexpr (I == Interpolation::None) {
      out[i] = detail::sampleAt(s, channel, k);
    } else if constexpr (I == Interpolation::Linear) {
      const float y1 = detail::sampleAt(s, channel, k), y2 = detail::sampleAt(s, channel, k + 1);
      out[i] = y1 + f * (y2 - y1);
    } else {
      out[i] = cubicHermite(f, detail::sampleAt(s, channel, k - 1), detail::sampleAt(s, channel, k),
                            detail::sampleAt(s, channel, k + 1), detail::sampleAt(s, channel, k + 2));
    }
  }
}

template <Interpolation I>
void readBlock(const SignalView& s, const float* positionMm, int positionStride, double originMm, double samplesPerMm,
               float* const* out, int numSamples) {
  const bool avx2 = KF_CORE_AVX2 && corePath() == CorePath::avx2;
  Piece p;
  for (int done = 0; done < numSamples; done += kPiece) {
    const int n = std::min(kPiece, numSamples - done);
    const float* pos = positionMm + done * positionStride;
#if KF_CORE_AVX2
    if constexpr (I == Interpolation::None) {
      // Mono none in one pass, where writing a sample's output cannot change a position not yet
      // read: the output is the position array itself, or apart from it.
      float* o = out[0] + done;
      const bool apart = o == pos || o + n <= pos || pos + (n - 1) * positionStride < o;
      if (avx2 && s.channels == 1 && apart) {
        if (!splitIndicesAvx2<I, true>(pos, positionStride, originMm, samplesPerMm, s.frames, n, p, s.data, o))
          readPadded<I>(s, 0, p, o, n);
        continue;
      }
    }
    const bool inside = avx2 ? splitIndicesAvx2<I>(pos, positionStride, originMm, samplesPerMm, s.frames, n, p)
                             : splitIndices<I>(pos, positionStride, originMm, samplesPerMm, s.frames, n, p);
#else
    const bool inside = splitIndices<I>(pos, positionStride, originMm, samplesPerMm, s.frames, n, p);
    (void)avx2;
#endif
    if (inside && s.channels == 1) {
      readInside<I, 1>(s.data, 1, p, out[0] + done, n);
    } else if (inside) {
      for (int c = 0; c < s.channels; ++c) readInside<I, 0>(s.data + c, s.channels, p, out[c] + done, n);
    } else {
      for (int c = 0; c < s.channels; ++c) readPadded<I>(s, c, p, out[c] + done, n);
    }
  }
}

}  // namespace

void readSpatialBlock(const SignalView& s, const float* positionMm, int positionStride, double originMm,
                      double samplesPerMm, Interpolation interpolation, float* const* out, int numSamples) {
  if (s.data == nullptr || s.frames <= 0 || s.channels <= 0) {
    for (int c = 0; c < std::max(s.channels, 0); ++c) std::fill_n(out[c], numSamples, 0.f);
    return;
  }
  if (s.frames > INT32_MAX - 4) {  // beyond the int32 whole parts: the per-sample reader
    for (int i = 0; i < numSamples; ++i) {
      const double index = spatialIndex(positionMm[i * positionStride], originMm, samplesPerMm);
      for (int c = 0; c < s.channels; ++c) out[c][i] = readSpatial(s, c, index, interpolation);
    }
    return;
  }
  switch (interpolation) {
    case Interpolation::None:
      return readBlock<Interpolation::None>(s, positionMm, positionStride, originMm, samplesPerMm, out, numSamples);
    case Interpolation::Linear:
      return readBlock<Interpolation::Linear>(s, positionMm, positionStride, originMm, samplesPerMm, out, numSamples);
    case Interpolation::Cubic:
    default:
      return readBlock<Interpolation::Cubic>(s, positionMm, positionStride, originMm, samplesPerMm, out, numSamples);
  }
}

}  // namespace kf
