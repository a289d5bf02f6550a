// The AVX2/FMA loops of LoudnessToFriction (LoudnessKernels.hpp), eight samples at a time. Only
// these functions are compiled for AVX2 (target attribute, not -mavx2 on the file), so nothing
// shared with the portable path, such as an inline function of the standard library, is.
#include "LoudnessKernels.hpp"

#if KF_CORE_AVX2

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#define KF_AVX2 __attribute__((target("avx2,fma")))

namespace kf::loudness {

namespace {

// Inclusive prefix sums of four doubles: (d0, d0 + d1, d0 + d1 + d2, d0 + .. + d3).
KF_AVX2 inline __m256d prefix4(__m256d d) {
  const __m256d zero = _mm256_setzero_pd();
  d = _mm256_add_pd(d, _mm256_blend_pd(_mm256_permute4x64_pd(d, _MM_SHUFFLE(2, 1, 0, 0)), zero, 0x1));
  return _mm256_add_pd(d, _mm256_permute2f128_pd(d, d, 0x08));  // + (0, 0, p0, p1)
}

// Eight samples of equation (1): the running sum s (in every lane) plus the prefix sums of
// a - old, in m0 (samples 0..3) and m1 (4..7), scaled, not clamped at 0; s moves on by the total.
// The serial dependency is one add per eight samples; the prefix sums hang off it.
__attribute__((target("avx2,fma"), always_inline)) inline void meansEight(const float* a, const float* old, __m256d& s,
                                                                          __m256d scale, __m256d& m0, __m256d& m1) {
  const __m256 a8 = _mm256_loadu_ps(a), o8 = _mm256_loadu_ps(old);
  __m256d d0 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(a8)), _mm256_cvtps_pd(_mm256_castps256_ps128(o8)));
  __m256d d1 =
      _mm256_sub_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(a8, 1)), _mm256_cvtps_pd(_mm256_extractf128_ps(o8, 1)));
  d0 = prefix4(d0);
  d1 = _mm256_add_pd(prefix4(d1), _mm256_permute4x64_pd(d0, 0xff));
  m0 = _mm256_mul_pd(_mm256_add_pd(s, d0), scale);
  m1 = _mm256_mul_pd(_mm256_add_pd(s, d1), scale);
  s = _mm256_add_pd(s, _mm256_permute4x64_pd(d1, 0xff));
}

}  // namespace

KF_AVX2 double runningMeansAvx2(const float* a, const float* old, double sum, double scale, double* means, int count) {
  const __m256d vScale = _mm256_set1_pd(scale);
  __m256d s = _mm256_set1_pd(sum);
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    __m256d m0, m1;
    meansEight(a + i, old + i, s, vScale, m0, m1);
    _mm256_storeu_pd(means + i, _mm256_max_pd(m0, _mm256_setzero_pd()));
    _mm256_storeu_pd(means + i + 4, _mm256_max_pd(m1, _mm256_setzero_pd()));
  }
  sum = _mm256_cvtsd_f64(s);
  for (; i < count; ++i) {
    sum += static_cast<double>(a[i]) - old[i];
    means[i] = std::max(sum, 0.0) * scale;
  }
  return sum;
}

KF_AVX2 double runningMeansAvx2(const float* a, const float* old, double sum, double scale, float* means, int count) {
  const __m256d vScale = _mm256_set1_pd(scale);
  __m256d s = _mm256_set1_pd(sum);
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    __m256d m0, m1;
    meansEight(a + i, old + i, s, vScale, m0, m1);
    // No clamp at 0 (the portable loop has one): the fast path's low bound is >= 1e-30, so a
    // sum rounded below 0 is at or below it and reads as silence all the same.
    _mm_storeu_ps(means + i, _mm256_cvtpd_ps(m0));
    _mm_storeu_ps(means + i + 4, _mm256_cvtpd_ps(m1));
  }
  sum = _mm256_cvtsd_f64(s);
  for (; i < count; ++i) {
    sum += static_cast<double>(a[i]) - old[i];
    means[i] = static_cast<float>(std::max(sum, 0.0) * scale);
  }
  return sum;
}

namespace {

// log2 of the mantissa m in [1, 2) by an eight-entry table: k = its top three bits, c_k the
// middle of its eighth of [1, 2), inv_k = 1/c_k in float and logInv_k = -log2(inv_k) (of the
// float inv_k, so that its rounding cancels); r = m inv_k - 1 (one FMA, |r| <= 1/17), and
// log2(m) = logInv_k + r Q(r), Q of degree 3 fitted (near-minimax, float coefficients) on
// |r| <= 1/17: 1.5e-8. The table reads are in-register permutes, not memory gathers. The
// portable polynomial's accuracy and better (kFastLog2Error holds), with 4 FMAs, not 7.
constexpr float kInv[8] = {9.411764741e-01f, 8.421052694e-01f, 7.619047761e-01f, 6.956521869e-01f,
                           6.399999857e-01f, 5.925925970e-01f, 5.517241359e-01f, 5.161290169e-01f};
constexpr float kLogInv[8] = {8.746283501e-02f, 2.479275018e-01f, 3.923173845e-01f, 5.235619545e-01f,
                              6.438562274e-01f, 7.548874617e-01f, 8.579810262e-01f, 9.541963339e-01f};
constexpr float kQ0 = 1.4426939728665729f, kQ1 = -0.7213456308511668f, kQ2 = 0.48214487603092465f,
                kQ3 = -0.36205431305810815f;

struct MapConstants {
  __m256 lo, hi, fLo, fHi, fMin, fMax, a, b, inv, logInv;
  KF_AVX2 explicit MapConstants(const FastMap& map)
      : lo(_mm256_set1_ps(map.loLevel)),
        hi(_mm256_set1_ps(map.hiLevel)),
        fLo(_mm256_set1_ps(map.forceAtLo)),
        fHi(_mm256_set1_ps(map.forceAtHi)),
        fMin(_mm256_set1_ps(map.minForce)),
        fMax(_mm256_set1_ps(map.maxForce)),
        a(_mm256_set1_ps(map.perLog2)),
        b(_mm256_set1_ps(map.atLog2Zero)),
        inv(_mm256_loadu_ps(kInv)),
        logInv(_mm256_loadu_ps(kLogInv)) {}
};

// mapFastPortable's clip and linear map on eight levels, the logarithm by the table above.
__attribute__((target("avx2,fma"), always_inline)) inline __m256 mapEight(const MapConstants& c, __m256 level) {
  const __m256 atLo = _mm256_cmp_ps(level, c.lo, _CMP_LE_OQ), atHi = _mm256_cmp_ps(level, c.hi, _CMP_GE_OQ);
  if (_mm256_movemask_ps(_mm256_or_ps(atLo, atHi)) == 0xff)  // all eight clipped: no logarithm
    return _mm256_blendv_ps(c.fLo, c.fHi, atHi);
  const __m256i bits = _mm256_castps_si256(_mm256_min_ps(_mm256_max_ps(level, c.lo), c.hi));
  const __m256 ex = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_srli_epi32(bits, 23), _mm256_set1_epi32(127)));
  const __m256 m = _mm256_castsi256_ps(
      _mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi32(0x007fffff)), _mm256_set1_epi32(0x3f800000)));
  const __m256i k = _mm256_srli_epi32(bits, 20);  // the permutes read its low three bits only
  const __m256 r = _mm256_fmsub_ps(m, _mm256_permutevar8x32_ps(c.inv, k), _mm256_set1_ps(1.f));
  __m256 q = _mm256_fmadd_ps(r, _mm256_set1_ps(kQ3), _mm256_set1_ps(kQ2));
  q = _mm256_fmadd_ps(r, q, _mm256_set1_ps(kQ1));
  q = _mm256_fmadd_ps(r, q, _mm256_set1_ps(kQ0));
  const __m256 log2 = _mm256_add_ps(ex, _mm256_fmadd_ps(r, q, _mm256_permutevar8x32_ps(c.logInv, k)));
  __m256 f = _mm256_min_ps(_mm256_max_ps(_mm256_fmadd_ps(log2, c.a, c.b), c.fMin), c.fMax);
  f = _mm256_blendv_ps(f, c.fLo, atLo);
  return _mm256_blendv_ps(f, c.fHi, atHi);  // hi wins, as in the exact path
}

}  // namespace

KF_AVX2 void mapFastAvx2(const FastMap& map, const float* levels, float* forceN, int count) {
  const MapConstants c(map);
  int i = 0;
  for (; i + 8 <= count; i += 8) _mm256_storeu_ps(forceN + i, mapEight(c, _mm256_loadu_ps(levels + i)));
  if (i < count) mapFastPortable(map, levels + i, forceN + i, count - i);
}

KF_AVX2 void sanitizeAvx2(const float* in, float* a, float maxAbs, int count) {
  const __m256 absMask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)), vMax = _mm256_set1_ps(maxAbs);
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    const __m256 x = _mm256_and_ps(_mm256_loadu_ps(in + i), absMask);
    // NaN -> 0 (an unordered compare is all zeros), then the clamp: Inf -> maxAbs.
    _mm256_storeu_ps(a + i, _mm256_min_ps(_mm256_and_ps(x, _mm256_cmp_ps(x, x, _CMP_ORD_Q)), vMax));
  }
  for (; i < count; ++i) {
    const float x = std::fabs(in[i]);
    a[i] = x <= maxAbs ? x : (x != x ? 0.f : maxAbs);
  }
}

}  // namespace kf::loudness

#endif  // KF_CORE_AVX2
