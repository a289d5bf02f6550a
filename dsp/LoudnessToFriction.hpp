// The paper's sound-to-friction conversion, equations (1) and (2):
//   (1) a_mu[t] = (1/n) * sum_{i=0}^{n-1} |a[t-i]|,  n = round(sampleRate * window)
//   (2) f[t] = mapping(20 log10(a_mu[t] / a_ref)), mapping clips to [loDb, hiDb] and maps
//       linearly onto [loForce, hiForce].
// The window may change while running, up to a maximum fixed at construction. The history
// lives in memory the caller owns (RTAlloc in the plugin), so nothing here allocates.
#pragma once

#include <cstdint>

#include "LoudnessKernels.hpp"
#include "PaperProfile.hpp"

namespace kf {

// The paper's mapping by default.
struct FrictionMapping {
  double loDb = paper::mapping::loDb;
  double hiDb = paper::mapping::hiDb;
  double loForceN = paper::mapping::loForceN;
  double hiForceN = paper::mapping::hiForceN;
  double ref = paper::mapping::ref;  // a_ref: the mean |a| that reads 0 dB
};

// The mapping setMapping uses for `wanted`: a level (loDb, hiDb) or force that is not finite,
// or a ref that is not finite and > 0, is the paper's value; a negative force is 0 N (friction
// never pushes). Everything else is kept: reversed bounds, a threshold (loDb == hiDb), huge values.
FrictionMapping usableMapping(const FrictionMapping& wanted);

// Equation (2) on one mean amplitude, in double: the reference the tests and benchmarks use.
double frictionFromMeanAbs(double meanAbs, const FrictionMapping& mapping);

// n = round(sampleRate * window), at least 1 and at most maxWindowSamples.
int windowSamples(double sampleRateHz, double windowS, int maxWindowSamples);

class LoudnessToFriction {
 public:
  // history: maxWindowSamples floats owned by the caller, for as long as this object lives.
  LoudnessToFriction(float* history, int maxWindowSamples);

  // Takes effect from the next sample; re-sums the window once when n changes.
  void setWindowSamples(int n);
  int windowSamples() const { return windowSamples_; }
  void setMapping(const FrictionMapping& mapping);

  // Force in N for each input sample, always within [loForce, hiForce] of the usable mapping.
  // NaN input counts as silence, Inf as the loudest level. in and forceN may be the same array.
  void process(const float* in, float* forceN, int numSamples);
  double meanAbs() const { return sum_ / windowSamples_; }
  // The force process() would give for `a` as the next sample, without taking it in: the
  // initial output a UGen shows before its first block.
  float peekForce(float a) const;
  // Whether equation (2) runs on the fast logarithm (the mapping's worst error with it is
  // within kMaxFastLogErrorN) or on the exact one.
  bool usesFastLog() const { return fastLog_; }
  // Worst force error the fast logarithm may add, by the bound setMapping() evaluates.
  static constexpr double kMaxFastLogErrorN = 5e-7;

  // Samples per two-pass piece of process(); longer blocks are processed in pieces.
  static constexpr int kPiece = 128;

 private:
  float mapMeanAbs(double meanAbs) const;
  float sanitizedAbs(float a) const;
  void resum();
  // The steps of a piece of process(): the input into the ring (takeIn), the running sum and
  // equation (2) by the kernels of the code path (LoudnessKernels.hpp), then afterPiece.
  // a, old: where the kernels read the piece's |a| and the values leaving the window, in the
  // ring itself where it can be, else in the copies.
  void takeIn(const float* in, int count, float* aCopy, float* oldCopy, const float*& a, const float*& old);
  void sanitizeInto(const float* in, float* a, int count) const;
  void afterPiece(int count);
  void mapExact(const double* means, float* forceN, int count) const;

  float* history_;
  int capacity_;
  int windowSamples_ = 1;
  int writeIndex_ = 0;  // where the next |a| goes; history_ is a ring of capacity_ samples
  int sinceResum_ = 0;  // samples taken in since the last re-sum
  double sum_ = 0.0;    // sum of the latest windowSamples_ values of |a|

  FrictionMapping mapping_;
  // The mapping precomputed so that most samples need no logarithm: at or below loAbs_ the
  // force is loForce, at or above hiAbs_ it is hiForce; in between, dB * forceSlope_ + offset.
  double loAbs_ = 0.0, hiAbs_ = 0.0;
  float forceAtLoAbs_ = 0.f, forceAtHiAbs_ = 0.f;
  // The force range, sorted: every output is clamped into it, so that neither the fast
  // logarithm's error nor rounding takes a force past loForce or hiForce.
  float minForce_ = 0.f, maxForce_ = 0.f;
  double forcePerDb_ = 0.0, forceOffset_ = 0.0, invRef_ = 1.0;
  float maxAbs_ = 1e30f;  // |a| taken into the sum is clamped here (see setMapping)
  // The fast path of equation (2), on the level mean / ref in float (LoudnessKernels.hpp).
  bool fastLog_ = false;
  loudness::FastMap fastMap_;
};

}  // namespace kf
