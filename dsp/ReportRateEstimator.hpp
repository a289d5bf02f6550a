// ReportRateEstimator: a mouse's report rate measured from its report times, for any rate
// from 125 Hz to 8 kHz.
//
// A mouse reports once per poll interval while it moves and sends nothing while still, and a
// slowly moving one skips intervals, so intervals are T, 2T, 3T... plus long silences. The
// estimate is the lower quartile of the last kWindow intervals shorter than kSilenceS: robust
// to silences, to skipped intervals (while at least a quarter are single ones) and to single
// outliers; intervals under kBurstS (reports read in one go) are not counted. Header-only, no allocation: used by the
// audio side (TrajectoryReconstructor) and by the device thread (status).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace kf {

class ReportRateEstimator {
 public:
  static constexpr int kWindow = 32;
  static constexpr int kMinIntervals = 16;   // before this, no estimate
  static constexpr double kSilenceS = 0.05;  // a longer interval is a still mouse (< 20 Hz)
  // A shorter one is no poll interval (8 kHz is 125 us): reports stamped on arrival that a late
  // reader took in one go.
  static constexpr double kBurstS = 0.0001;

  void reset() { *this = ReportRateEstimator{}; }

  // Report times in order (s, any clock). Returns true when the estimate changed.
  bool addReport(double timeS) {
    if (!std::isfinite(timeS)) return false;
    const bool hadLast = hasLast_;
    const double intervalS = timeS - lastS_;
    hasLast_ = true;
    lastS_ = timeS;
    if (!hadLast || !(intervalS >= kBurstS) || intervalS >= kSilenceS) return false;
    intervals_[next_] = intervalS;
    next_ = (next_ + 1) % kWindow;
    count_ = std::min(count_ + 1, kWindow);
    if (count_ < kMinIntervals) return false;
    std::array<double, kWindow> sorted;
    std::copy_n(intervals_.begin(), count_, sorted.begin());
    auto quartile = sorted.begin() + count_ / 4;
    std::nth_element(sorted.begin(), quartile, sorted.begin() + count_);
    const double previous = periodS_;
    periodS_ = *quartile;
    return periodS_ != previous;
  }

  // USB mice poll at 125 Hz x 2^k (up to 8 kHz): a measured rate within 5% of one is that
  // one, so that speed steps (one count per T) stay exact under timing jitter; others stand.
  static double snapToUsbRateHz(double rateHz) {
    for (double usbHz = 125.0; usbHz <= 8000.0; usbHz *= 2.0)
      if (std::fabs(rateHz - usbHz) <= 0.05 * usbHz) return usbHz;
    return rateHz;
  }

  bool hasEstimate() const { return periodS_ > 0.0; }
  // 0 before kMinIntervals intervals were seen.
  double periodS() const { return periodS_; }
  double rateHz() const { return periodS_ > 0.0 ? 1.0 / periodS_ : 0.0; }

 private:
  std::array<double, kWindow> intervals_{};
  int next_ = 0;
  int count_ = 0;
  bool hasLast_ = false;
  double lastS_ = 0.0;
  double periodS_ = 0.0;
};

}  // namespace kf
