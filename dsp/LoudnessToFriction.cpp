#include "LoudnessToFriction.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

namespace {

inline bool isUsable(double v) { return std::isfinite(v); }

}  // namespace

double frictionFromMeanAbs(double meanAbs, const FrictionMapping& m) {
  const double lo = std::min(m.loDb, m.hiDb), hi = std::max(m.loDb, m.hiDb);
  const double db = meanAbs > 0.0 ? 20.0 * std::log10(meanAbs / m.ref) : -HUGE_VAL;
  const double clipped = std::clamp(db, lo, hi);
  if (m.hiDb == m.loDb) return db >= m.hiDb ? m.hiForceN : m.loForceN;
  return m.loForceN + (clipped - m.loDb) / (m.hiDb - m.loDb) * (m.hiForceN - m.loForceN);
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

void LoudnessToFriction::resum() {
  double sum = 0.0;
  int k = writeIndex_;
  for (int i = 0; i < windowSamples_; ++i) {
    k = (k == 0 ? capacity_ : k) - 1;
    sum += history_[k];
  }
  sum_ = sum;
}

void LoudnessToFriction::setMapping(const FrictionMapping& wanted) {
  FrictionMapping m = wanted;
  // Parameters that would make the mapping undefined fall back to the paper's values.
  const FrictionMapping paper;
  if (!isUsable(m.loDb)) m.loDb = paper.loDb;
  if (!isUsable(m.hiDb)) m.hiDb = paper.hiDb;
  if (!isUsable(m.loForceN)) m.loForceN = paper.loForceN;
  if (!isUsable(m.hiForceN)) m.hiForceN = paper.hiForceN;
  if (!(isUsable(m.ref) && m.ref > 0.0)) m.ref = paper.ref;
  mapping_ = m;

  // Reversed dB bounds give an inverse mapping: the clip is on the sorted bounds.
  const bool rising = m.hiDb >= m.loDb;
  const double lowDb = rising ? m.loDb : m.hiDb, highDb = rising ? m.hiDb : m.loDb;
  loAbs_ = m.ref * std::pow(10.0, lowDb / 20.0);
  hiAbs_ = m.ref * std::pow(10.0, highDb / 20.0);
  forceAtLoAbs_ = static_cast<float>(rising ? m.loForceN : m.hiForceN);
  forceAtHiAbs_ = static_cast<float>(rising ? m.hiForceN : m.loForceN);
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
  const double db = 20.0 * std::log10(meanAbs * invRef_);
  return static_cast<float>(db * forcePerDb_ + forceOffset_);
}

float LoudnessToFriction::peekForce(float a) const {
  const float x = sanitizedAbs(a);
  int oldest = writeIndex_ - windowSamples_;
  if (oldest < 0) oldest += capacity_;
  return mapMeanAbs(std::max(sum_ + x - history_[oldest], 0.0) / windowSamples_);
}

void LoudnessToFriction::process(const float* in, float* forceN, int numSamples) {
  const int n = windowSamples_;
  const double invN = 1.0 / n;
  double sum = sum_;
  int w = writeIndex_;
  for (int i = 0; i < numSamples; ++i) {
    // Equation (1) as a running sum: add the newest |a|, drop the one n samples back.
    const float x = sanitizedAbs(in[i]);
    int oldest = w - n;
    if (oldest < 0) oldest += capacity_;
    sum += static_cast<double>(x) - history_[oldest];
    history_[w] = x;
    if (++w == capacity_) {
      w = 0;
      writeIndex_ = 0;
      sum_ = sum;
      // Re-sum once per lap of the ring, so rounding cannot accumulate: the sum never carries
      // more than capacity_ additions' worth of error, however long it runs.
      resum();
      sum = sum_;
    }
    forceN[i] = mapMeanAbs(std::max(sum, 0.0) * invN);
  }
  sum_ = sum;
  writeIndex_ = w;
}

}  // namespace kf
