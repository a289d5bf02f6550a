// The vector loops of LoudnessToFriction::process, one set per code path (CorePath.hpp). Internal
// to dsp/: the class holds the state, these only compute over a piece's arrays.
#pragma once

#include <cstdint>

#include "CorePath.hpp"

namespace kf::loudness {

// log2 of a positive normal float on the portable path: the exponent from the bits, the
// mantissa folded into [sqrt(1/2), sqrt(2)), log2(1 + t) = t P(t) with P of degree 6 fitted
// (minimax, float coefficients) on t in [-0.293, 0.415]. The AVX2 path has its own (an
// eight-entry table and degree 4, LoudnessKernelsAvx2.cpp). Worst error against std::log2 in
// double over every float in [0.5, 2) (every mantissa, both sides of the fold), the float sum
// e + t P included: 3.98e-7 portable, 8.5e-8 AVX2. kFastLog2Error holds for both; setMapping
// adds the sum's rounding at larger exponents on top.
constexpr double kFastLog2Error = 4e-7;
constexpr float kP0 = 1.4426996708f, kP1 = -0.7213758826f, kP2 = 0.4804650247f, kP3 = -0.3589618504f,
                kP4 = 0.2972626686f, kP5 = -0.2726978362f, kP6 = 0.1706340909f;
constexpr int32_t kSqrt2Bits = 0x3fb504f3;

// Equation (2) on the fast logarithm, for a level = mean / ref: clip in the linear domain to
// [loLevel, hiLevel], then force = log2(level) * perLog2 + atLog2Zero clamped to
// [minForce, maxForce]; at or below loLevel exactly forceAtLo, at or above hiLevel forceAtHi.
struct FastMap {
  float loLevel = 0.f, hiLevel = 1.f, forceAtLo = 0.f, forceAtHi = 0.f, minForce = 0.f, maxForce = 0.f, perLog2 = 0.f,
        atLog2Zero = 0.f;
};

// Equation (1) over a piece: sum += a[i] - old[i] in double (a: the new |a|, old: the values
// leaving the window), means[i] = max(sum, 0) * scale. Returns the sum after the piece.
double runningMeansPortable(const float* a, const float* old, double sum, double scale, float* means, int count);
double runningMeansPortable(const float* a, const float* old, double sum, double scale, double* means, int count);
void mapFastPortable(const FastMap& map, const float* levels, float* forceN, int count);

#if KF_CORE_AVX2
// The same, eight samples at a time (the polynomial in FMA): only to be called where
// cpuHasAvx2Fma(). Two loops, not one: fused, the running sum's serial adds and the mapping's
// branch left the out-of-order core less to overlap (1.9 against 1.4 ns a sample, measured).
double runningMeansAvx2(const float* a, const float* old, double sum, double scale, float* means, int count);
double runningMeansAvx2(const float* a, const float* old, double sum, double scale, double* means, int count);
void mapFastAvx2(const FastMap& map, const float* levels, float* forceN, int count);
// a = |in| with NaN -> 0 and clamped at maxAbs, as LoudnessToFriction::sanitizeInto.
void sanitizeAvx2(const float* in, float* a, float maxAbs, int count);
#endif

}  // namespace kf::loudness
