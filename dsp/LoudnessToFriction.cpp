#include "LoudnessToFriction.hpp"

#include "LoudnessKernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kf {

namespace {

inline bool isUsable(double v) { return std::isfinite(v); }

constexpr double kLog10OfE = 0.43429448190325182765;
constexpr double kLog10Of2 = 0.30102999566398119521;

using loudness::FastMap;

inline float fastLog2(float x) {
  using namespace loudness;
  int32_t bits;
  std::memcpy(&bits, &x, 4);
  int32_t ex = (bits >> 23) - 127;
  int32_t mbits = (bits & 0x007fffff) | 0x3f800000;
  const int32_t big = mbits > kSqrt2Bits ? 1 : 0;  // mantissa above sqrt(2): halve it
  mbits -= big << 23;
  ex += big;
  float m;
  std::memcpy(&m, &mbits, 4);
  const float t = m - 1.f;
  const float p = kP0 + t * (kP1 + t * (kP2 + t * (kP3 + t * (kP4 + t * (kP5 + t * kP6)))));
  return static_cast<float>(ex) + t * p;
}

}  // namespace

double frictionFromMeanAbs(double meanAbs, const FrictionMapping& m) {
  const double lo = std::min(m.loDb, m.hiDb), hi = std::max(m.loDb, m.hiDb);
  const double db = meanAbs > 0.0 ? 20.0 * std::log10(meanAbs / m.ref) : -HUGE_VAL;
  const double clipped = std::clamp(db, lo, hi);
  if (m.hiDb == m.loDb) return db >= m.hiDb ? m.hiForceN : m.loForceN;
  return m.loForceN + (clipped - m.loDb) / (m.hiDb - m.loDb) * (m.hiForceN - m.loForceN);
}

FrictionMapping usableMapping(const FrictionMapping& wanted) {
  const FrictionMapping paper;
  const auto force = [](double n, double paperN) { return isUsable(n) ? std::max(n, 0.0) : paperN; };
  FrictionMapping m;
  m.loDb = isUsable(wanted.loDb) ? wanted.loDb : paper.loDb;
  m.hiDb = isUsable(wanted.hiDb) ? wanted.hiDb : paper.hiDb;
  m.loForceN = force(wanted.loForceN, paper.loForceN);
  m.hiForceN = force(wanted.hiForceN, paper.hiForceN);
  m.ref = isUsable(wanted.ref) && wanted.ref > 0.0 ? wanted.ref : paper.ref;
  return m;
}

int windowSamples(double sampleRateHz, double windowS, int maxWindowSamples) {
  const double n = std::round(sampleRateHz * windowS);
  if (!(n >= 1.0)) return 1;  // also NaN
  return n >= maxWindowSamples ? std::max(1, maxWindowSamples) : static_cast<int>(n);
}

LoudnessToFriction::LoudnessToFriction(float* history, int maxWindowSamples)
    : history_(history), capacity_(std::max(1, maxWindowSamples)) {
  std::fill(history_, history_ + capacity_, 0.f);  // silence before the start
  setMapping(FrictionMapping{});
}

void LoudnessToFriction::setWindowSamples(int n) {
  n = std::clamp(n, 1, capacity_);
  if (n == windowSamples_) return;
  windowSamples_ = n;
  resum();
}

namespace {

// Sum of count floats in double, in four independent chains (the adds pipeline).
double sumOf(const float* x, int count) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  int i = 0;
  for (; i + 4 <= count; i += 4) {
    s0 += x[i];
    s1 += x[i + 1];
    s2 += x[i + 2];
    s3 += x[i + 3];
  }
  for (; i < count; ++i) s0 += x[i];
  return (s0 + s1) + (s2 + s3);
}

}  // namespace

void LoudnessToFriction::resum() {
  // The window is the n values before writeIndex_: one run, or two where it wraps.
  const int n = windowSamples_, w = writeIndex_;
  if (n <= w)
    sum_ = sumOf(history_ + w - n, n);
  else
    sum_ = sumOf(history_ + capacity_ - (n - w), n - w) + sumOf(history_, w);
}

void LoudnessToFriction::setMapping(const FrictionMapping& wanted) {
  const FrictionMapping m = usableMapping(wanted);
  mapping_ = m;

  // Reversed dB bounds give an inverse mapping: the clip is on the sorted bounds.
  const bool rising = m.hiDb >= m.loDb;
  const double lowDb = rising ? m.loDb : m.hiDb, highDb = rising ? m.hiDb : m.loDb;
  loAbs_ = m.ref * std::pow(10.0, lowDb / 20.0);
  hiAbs_ = m.ref * std::pow(10.0, highDb / 20.0);
  forceAtLoAbs_ = static_cast<float>(rising ? m.loForceN : m.hiForceN);
  forceAtHiAbs_ = static_cast<float>(rising ? m.hiForceN : m.loForceN);
  minForce_ = std::min(forceAtLoAbs_, forceAtHiAbs_);
  maxForce_ = std::max(forceAtLoAbs_, forceAtHiAbs_);
  invRef_ = 1.0 / m.ref;
  // One sample at hiAbs_ * capacity_ saturates any window by itself, so clamping there changes
  // no output, and it keeps a huge value from wiping out the precision of the running sum.
  maxAbs_ = static_cast<float>(std::min(hiAbs_ * capacity_, 1e30));
  if (m.hiDb == m.loDb) {
    forcePerDb_ = 0.0;
    forceOffset_ = m.hiForceN;
  } else {
    forcePerDb_ = (m.hiForceN - m.loForceN) / (m.hiDb - m.loDb);
    forceOffset_ = m.loForceN - m.loDb * forcePerDb_;
  }

  // The fast path, on level = mean / ref: force = 20 log10(level) * forcePerDb + offset
  // = log2(level) * (20 log10(2) forcePerDb) + offset. Taken only where a bound on its error
  // (logarithm, float level and float arithmetic) stays within kMaxFastLogErrorN; a threshold
  // (loDb == hiDb) or a steep or far-offset mapping keeps the exact path.
  const double loLevel = std::pow(10.0, lowDb / 20.0), hiLevel = std::pow(10.0, highDb / 20.0);
  const double forcePerLog2 = 20.0 * kLog10Of2 * forcePerDb_;
  const double maxLog2 = std::max({1.0, std::fabs(std::log2(loLevel)), std::fabs(std::log2(hiLevel))});
  const double maxForce = std::max({std::fabs(m.loForceN), std::fabs(m.hiForceN), std::fabs(forceOffset_)});
  // log2 error: the polynomial, the float level (2^-24 relative), the float sum e + t P
  // (half an ulp of maxLog2); then the float product and sum (an ulp of maxForce each).
  const double log2Error = loudness::kFastLog2Error + 1.5 * 0x1p-24 + maxLog2 * 0x1p-23;
  const double boundN = std::fabs(forcePerLog2) * log2Error + 2.0 * maxForce * 0x1p-23;
  fastLog_ = m.hiDb != m.loDb && loLevel >= 1e-30 && hiLevel <= 1e30 && boundN <= kMaxFastLogErrorN;
  fastMap_ = {static_cast<float>(loLevel),
              static_cast<float>(hiLevel),
              forceAtLoAbs_,
              forceAtHiAbs_,
              minForce_,
              maxForce_,
              static_cast<float>(forcePerLog2),
              static_cast<float>(forceOffset_)};
}

inline float LoudnessToFriction::sanitizedAbs(float a) const {
  const float x = std::fabs(a);
  if (x <= maxAbs_) return x;
  return std::isnan(x) ? 0.f : maxAbs_;  // NaN is silence, Inf the loudest there is
}

inline float LoudnessToFriction::mapMeanAbs(double meanAbs) const {
  // hi first, so that with loDb == hiDb the level itself reads hiForce, as in the reference.
  if (meanAbs >= hiAbs_) return forceAtHiAbs_;
  if (meanAbs <= loAbs_) return forceAtLoAbs_;
  // Equation (2) inside the clip range: 20 log10(mean / ref) mapped linearly.
  // 20 log10(x) as 20 log10(e) ln(x): the same error, and glibc's log is much faster than log10.
  const double db = (20.0 * kLog10OfE) * std::log(meanAbs * invRef_);
  return std::clamp(static_cast<float>(db * forcePerDb_ + forceOffset_), minForce_, maxForce_);
}

float LoudnessToFriction::peekForce(float a) const {
  const float x = sanitizedAbs(a);
  int oldest = writeIndex_ - windowSamples_;
  if (oldest < 0) oldest += capacity_;
  return mapMeanAbs(std::max(sum_ + x - history_[oldest], 0.0) / windowSamples_);
}

void LoudnessToFriction::process(const float* in, float* forceN, int numSamples) {
  const bool avx2 = KF_CORE_AVX2 && corePath() == CorePath::avx2;
  for (int done = 0; done < numSamples; done += kPiece) {
    const int count = std::min(kPiece, numSamples - done);
    float aCopy[kPiece], oldCopy[kPiece];
    const float *a = aCopy, *old = oldCopy;
    takeIn(in + done, count, aCopy, oldCopy, a, old);
    if (fastLog_) {
      const double scale = invRef_ / windowSamples_;
      alignas(32) float levels[kPiece];
#if KF_CORE_AVX2
      if (avx2) {
        sum_ = loudness::runningMeansAvx2(a, old, sum_, scale, levels, count);
        loudness::mapFastAvx2(fastMap_, levels, forceN + done, count);
        afterPiece(count);
        continue;
      }
#endif
      sum_ = loudness::runningMeansPortable(a, old, sum_, scale, levels, count);
      loudness::mapFastPortable(fastMap_, levels, forceN + done, count);
    } else {
      alignas(32) double means[kPiece];
#if KF_CORE_AVX2
      if (avx2)
        sum_ = loudness::runningMeansAvx2(a, old, sum_, 1.0 / windowSamples_, means, count);
      else
#endif
        sum_ = loudness::runningMeansPortable(a, old, sum_, 1.0 / windowSamples_, means, count);
      mapExact(means, forceN + done, count);
    }
    afterPiece(count);
  }
}

// A piece's input taken in: a = |in| sanitized, old = the values leaving the window, and a written
// into the ring. The ring is read and written in contiguous runs, without a wrap test per sample.
void LoudnessToFriction::sanitizeInto(const float* in, float* a, int count) const {
#if KF_CORE_AVX2
  if (corePath() == CorePath::avx2) return loudness::sanitizeAvx2(in, a, maxAbs_, count);
#endif
#if defined(__SSE2__)
  const __m128 absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)), maxAbs = _mm_set1_ps(maxAbs_);
  int i = 0;
  for (; i + 4 <= count; i += 4) {
    const __m128 x = _mm_and_ps(_mm_loadu_ps(in + i), absMask);
    // NaN -> 0 (an unordered compare is all zeros), then the clamp: Inf -> maxAbs.
    _mm_storeu_ps(a + i, _mm_min_ps(_mm_and_ps(x, _mm_cmpord_ps(x, x)), maxAbs));
  }
  for (; i < count; ++i) a[i] = sanitizedAbs(in[i]);
#else
  for (int i = 0; i < count; ++i) a[i] = sanitizedAbs(in[i]);
#endif
}

void LoudnessToFriction::takeIn(const float* in, int count, float* aCopy, float* oldCopy, const float*& a,
                                const float*& old) {
  const int n = windowSamples_, cap = capacity_, w0 = writeIndex_;
  if (w0 >= n && w0 + count <= cap && cap >= n + count) {
    // Most pieces: the piece and the window before it lie in the ring without a wrap, and the
    // ring is long enough that writing the piece overwrites nothing still to leave. The new
    // values go straight into the ring, and both runs are read there: no copies.
    float* at = history_ + w0;
    sanitizeInto(in, at, count);
    a = at;
    old = at - n;
    writeIndex_ = w0 + count == cap ? 0 : w0 + count;
    return;
  }
  sanitizeInto(in, aCopy, count);
  a = aCopy;
  old = oldCopy;

  // The values leaving the window: from the ring for the first min(n, count) samples, from this
  // piece after that.
  const int fromRing = std::min(n, count);
  int oldest = writeIndex_ - n;
  if (oldest < 0) oldest += cap;
  for (int i = 0; i < fromRing;) {
    const int run = std::min(fromRing - i, cap - oldest);
    std::memcpy(oldCopy + i, history_ + oldest, sizeof(float) * run);
    i += run;
    oldest += run;
    if (oldest == cap) oldest = 0;
  }
  if (count > fromRing) std::memcpy(oldCopy + fromRing, aCopy, sizeof(float) * (count - fromRing));

  // Into the ring: only the last cap values matter when the piece is longer than the ring.
  const int keep = std::min(count, cap);
  int w = (writeIndex_ + (count - keep)) % cap;
  for (int i = count - keep; i < count;) {
    const int run = std::min(count - i, cap - w);
    std::memcpy(history_ + w, aCopy + i, sizeof(float) * run);
    i += run;
    w += run;
    if (w == cap) w = 0;
  }
  writeIndex_ = w;
}

void LoudnessToFriction::afterPiece(int count) {
  // Re-sum once per lap of the ring, so rounding cannot accumulate: the sum never carries more
  // than capacity_ + kPiece additions' worth of error, however long it runs.
  sinceResum_ += count;
  if (sinceResum_ >= capacity_) {
    sinceResum_ = 0;
    resum();
  }
}

namespace loudness {

// Equation (1), four at a time: the differences (newest in, oldest out) in double, then prefix
// sums of each group of four in two double pairs, each added to the running sum, which then
// moves on by the group's total: one add per four samples on the serial path.
template <typename Mean>
double runningMeansSse(const float* a, const float* old, double sum, double scale, Mean* means, int count) {
  double diff[LoudnessToFriction::kPiece];
  for (int k = 0; k < count; ++k) diff[k] = static_cast<double>(a[k]) - old[k];
  int i = 0;
#if defined(__SSE2__)
  {
    const __m128d zero = _mm_setzero_pd(), vScale = _mm_set1_pd(scale);
    __m128d s = _mm_set1_pd(sum);
    for (; i + 4 <= count; i += 4) {
      __m128d d01 = _mm_loadu_pd(diff + i), d23 = _mm_loadu_pd(diff + i + 2);
      d01 = _mm_add_pd(d01, _mm_unpacklo_pd(zero, d01));  // (d0, d0 + d1)
      d23 = _mm_add_pd(d23, _mm_unpacklo_pd(zero, d23));  // (d2, d2 + d3)
      d23 = _mm_add_pd(d23, _mm_unpackhi_pd(d01, d01));   // (d0 + d1 + d2, d0 + .. + d3)
      const __m128d m01 = _mm_mul_pd(_mm_max_pd(_mm_add_pd(s, d01), zero), vScale);
      const __m128d m23 = _mm_mul_pd(_mm_max_pd(_mm_add_pd(s, d23), zero), vScale);
      s = _mm_add_pd(s, _mm_unpackhi_pd(d23, d23));
      if constexpr (std::is_same_v<Mean, float>) {
        _mm_storeu_ps(means + i, _mm_movelh_ps(_mm_cvtpd_ps(m01), _mm_cvtpd_ps(m23)));
      } else {
        _mm_storeu_pd(means + i, m01);
        _mm_storeu_pd(means + i + 2, m23);
      }
    }
    sum = _mm_cvtsd_f64(s);
  }
#endif
  for (; i < count; ++i) {
    sum += diff[i];
    means[i] = static_cast<Mean>(std::max(sum, 0.0) * scale);
  }
  return sum;
}

double runningMeansPortable(const float* a, const float* old, double sum, double scale, float* means, int count) {
  return runningMeansSse(a, old, sum, scale, means, count);
}

double runningMeansPortable(const float* a, const float* old, double sum, double scale, double* means, int count) {
  return runningMeansSse(a, old, sum, scale, means, count);
}

// Equation (2) on the fast logarithm, branch-free: clip in the linear domain, log2 by bits and
// polynomial, the linear map, then the clip values where the level is at or beyond a bound.
void mapFastPortable(const FastMap& map, const float* levels, float* forceN, int count) {
  int i = 0;
#if defined(__SSE2__)
  {
    const __m128 lo = _mm_set1_ps(map.loLevel), hi = _mm_set1_ps(map.hiLevel);
    const __m128 fLo = _mm_set1_ps(map.forceAtLo), fHi = _mm_set1_ps(map.forceAtHi);
    const __m128 fMin = _mm_set1_ps(map.minForce), fMax = _mm_set1_ps(map.maxForce);
    const __m128 a = _mm_set1_ps(map.perLog2), b = _mm_set1_ps(map.atLog2Zero);
    const __m128i mantMask = _mm_set1_epi32(0x007fffff), one = _mm_set1_epi32(0x3f800000);
    const __m128i sqrt2 = _mm_set1_epi32(kSqrt2Bits), bias = _mm_set1_epi32(127);
    const __m128i halfBit = _mm_set1_epi32(1 << 23);
    for (; i + 4 <= count; i += 4) {
      const __m128 level = _mm_loadu_ps(levels + i);
      const __m128 atLo = _mm_cmple_ps(level, lo), atHi = _mm_cmpge_ps(level, hi);
      const int clipped = _mm_movemask_ps(_mm_or_ps(atLo, atHi));
      if (clipped == 0xf) {  // all four clipped (silence, or loud): no logarithm
        _mm_storeu_ps(forceN + i, _mm_or_ps(_mm_and_ps(atHi, fHi), _mm_andnot_ps(atHi, fLo)));
        continue;
      }
      const __m128 m = _mm_min_ps(_mm_max_ps(level, lo), hi);
      const __m128i bits = _mm_castps_si128(m);
      __m128i ex = _mm_sub_epi32(_mm_srli_epi32(bits, 23), bias);
      __m128i mbits = _mm_or_si128(_mm_and_si128(bits, mantMask), one);
      const __m128i big = _mm_cmpgt_epi32(mbits, sqrt2);  // all ones where the mantissa > sqrt(2)
      mbits = _mm_sub_epi32(mbits, _mm_and_si128(big, halfBit));
      ex = _mm_sub_epi32(ex, big);
      const __m128 t = _mm_sub_ps(_mm_castsi128_ps(mbits), _mm_set1_ps(1.f));
      __m128 p = _mm_add_ps(_mm_set1_ps(kP5), _mm_mul_ps(t, _mm_set1_ps(kP6)));
      p = _mm_add_ps(_mm_set1_ps(kP4), _mm_mul_ps(t, p));
      p = _mm_add_ps(_mm_set1_ps(kP3), _mm_mul_ps(t, p));
      p = _mm_add_ps(_mm_set1_ps(kP2), _mm_mul_ps(t, p));
      p = _mm_add_ps(_mm_set1_ps(kP1), _mm_mul_ps(t, p));
      p = _mm_add_ps(_mm_set1_ps(kP0), _mm_mul_ps(t, p));
      const __m128 log2 = _mm_add_ps(_mm_cvtepi32_ps(ex), _mm_mul_ps(t, p));
      __m128 f = _mm_min_ps(_mm_max_ps(_mm_add_ps(_mm_mul_ps(log2, a), b), fMin), fMax);
      f = _mm_or_ps(_mm_and_ps(atLo, fLo), _mm_andnot_ps(atLo, f));
      f = _mm_or_ps(_mm_and_ps(atHi, fHi), _mm_andnot_ps(atHi, f));  // hi wins, as in mapMeanAbs
      _mm_storeu_ps(forceN + i, f);
    }
  }
#endif
  for (; i < count; ++i) {  // the same operations, one at a time
    const float level = levels[i];
    const float m = std::min(std::max(level, map.loLevel), map.hiLevel);
    const float f = std::clamp(fastLog2(m) * map.perLog2 + map.atLog2Zero, map.minForce, map.maxForce);
    forceN[i] = level >= map.hiLevel ? map.forceAtHi : (level <= map.loLevel ? map.forceAtLo : f);
  }
}

}  // namespace loudness

void LoudnessToFriction::mapExact(const double* means, float* forceN, int count) const {
  for (int i = 0; i < count; ++i) forceN[i] = mapMeanAbs(means[i]);
}

}  // namespace kf
