#include "TrajectoryReconstructor.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

namespace {

// In update intervals T (see the header).
constexpr double kExtrapolateT = 1.5;  // predictive: carry the motion on this long at most
constexpr double kStaleT = 2.0;        // no report for this long: the puck has stopped
constexpr double kFadeT = 1.0;         // then speed (and extrapolation) go to 0 over this

constexpr uint32_t kAfterLossFlag = 2;  // ReportFlag::kAfterLoss (device/core/spec/Report.hpp)

// The first k in [lo, hi) where isPast(k) holds, hi if none; isPast must be false up to some k
// and true from there on.
template <typename Predicate>
int firstSampleWhere(int lo, int hi, Predicate isPast) {
  // Most runs lie wholly on one side (no report due, no stretch end crossed): one test settles it.
  if (lo == hi || !isPast(hi - 1)) return hi;
  if (isPast(lo)) return lo;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (isPast(mid))
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

}  // namespace

TrajectoryMode trajectoryModeFromCode(int code) {
  switch (code) {
    case 0:
      return TrajectoryMode::Hold;
    case 2:
      return TrajectoryMode::Predictive;
    default:
      return TrajectoryMode::Linear;
  }
}

TrajectoryReconstructor::TrajectoryReconstructor(double updateRateHz, TrajectoryMode mode)
    : nominalIntervalS_(1.0 / (updateRateHz > 0.0 ? updateRateHz : paper::device::updateRateHz)),
      intervalS_(nominalIntervalS_),
      mode_(mode),
      nextMode_(mode) {}

void TrajectoryReconstructor::reset() {
  axes_ = {};
  hasAnchor_ = false;
  hasRendered_ = false;
  renderedMm_[0] = renderedMm_[1] = 0.0;
  renderedSpeedMmPerS_[0] = renderedSpeedMmPerS_[1] = 0.0;
  pendingHead_ = 0;
  pendingCount_ = 0;
  mode_ = nextMode_;
  rate_.reset();
  intervalS_ = nominalIntervalS_;
}

void TrajectoryReconstructor::resetAt(double xMm, double yMm) {
  reset();
  axes_[0].anchorMm = std::isfinite(xMm) ? xMm : 0.0;
  axes_[1].anchorMm = std::isfinite(yMm) ? yMm : 0.0;
  renderedMm_[0] = axes_[0].anchorMm;
  renderedMm_[1] = axes_[1].anchorMm;
}

void TrajectoryReconstructor::addReport(double reportTimeS, double dxMm, double dyMm, uint32_t flags,
                                        double sourceTimeS) {
  if (flags & kAfterLossFlag) ++reportsAfterLoss_;
  // The update rate is measured on the device's own clock where there is one.
  const double rateTimeS = std::isfinite(sourceTimeS) ? sourceTimeS : reportTimeS;
  if (std::isfinite(rateTimeS)) rate_.addReport(rateTimeS);
  enqueue(reportTimeS, dxMm, dyMm);
}

void TrajectoryReconstructor::addShift(double /*timeS*/, double dxMm, double dyMm) {
  // Anchor and everything relative to it move together: the output steps by the shift.
  if (std::isfinite(dxMm)) axes_[0].anchorMm += dxMm;
  if (std::isfinite(dyMm)) axes_[1].anchorMm += dyMm;
}

void TrajectoryReconstructor::enqueue(double timeS, double dxMm, double dyMm) {
  if (!std::isfinite(dxMm)) dxMm = 0.0;  // one bad report must not poison the position
  if (!std::isfinite(dyMm)) dyMm = 0.0;
  if (!std::isfinite(timeS)) timeS = pendingCount_ > 0 ? lastQueuedTimeS_ : lastRenderTimeS_;
  if (pendingCount_ > 0) timeS = std::max(timeS, lastQueuedTimeS_);
  if (pendingCount_ == kQueueCapacity) {
    // Full: never drop distance; the newest entry absorbs this one.
    Pending& newest = queue_[(pendingHead_ + pendingCount_ - 1) % kQueueCapacity];
    newest.dMm[0] += dxMm;
    newest.dMm[1] += dyMm;
    ++reportsMerged_;
    return;
  }
  queue_[(pendingHead_ + pendingCount_) % kQueueCapacity] = Pending{timeS, {dxMm, dyMm}};
  ++pendingCount_;
  lastQueuedTimeS_ = timeS;
}

double TrajectoryReconstructor::positionAt(const Axis& axis, double s) const {
  double extrapolateT = 0.0;
  double fade = 0.0;
  if (mode_ == TrajectoryMode::Predictive) {
    if (s < kExtrapolateT)
      extrapolateT = std::max(0.0, s);
    else if (s < kStaleT)
      extrapolateT = kExtrapolateT;
    else if (s < kStaleT + kFadeT)
      extrapolateT = kExtrapolateT * (1.0 - (s - kStaleT) / kFadeT);
  }
  if (mode_ != TrajectoryMode::Hold && s < 1.0) fade = 1.0 - std::max(0.0, s);
  if (extrapolateT == 0.0 && fade == 0.0) return axis.anchorMm;  // exactly the reported sum
  return blend(axis, extrapolateT, fade);
}

double TrajectoryReconstructor::speedAt(const Axis& axis, double s) const {
  if (s < kStaleT) return axis.speedMmPerS;
  if (s < kStaleT + kFadeT) return axis.speedMmPerS * (1.0 - (s - kStaleT) / kFadeT);
  return 0.0;
}

void TrajectoryReconstructor::take(const Pending& report, double nowS) {
  // Taken at its own time, or at the last rendered sample if that is already past it, so the
  // position just before it is what was (or would have been) output.
  double takeS = std::min(report.timeS, nowS);
  if (hasRendered_) takeS = std::max(takeS, lastRenderTimeS_);
  double beforeMm[2];
  const double phase = (takeS - anchorTimeS_) / intervalS_;
  for (int a = 0; a < 2; ++a) beforeMm[a] = hasAnchor_ ? positionAt(axes_[a], phase) : axes_[a].anchorMm;
  // The new T applies from this report on (positions before it were rendered with the old).
  const double measuredS = rate_.hasEstimate() ? 1.0 / ReportRateEstimator::snapToUsbRateHz(rate_.rateHz()) : 0.0;
  intervalS_ = measuredS > 0.0 && std::fabs(measuredS - nominalIntervalS_) > kRateBand * nominalIntervalS_
                   ? measuredS
                   : nominalIntervalS_;
  for (int a = 0; a < 2; ++a) {
    Axis& axis = axes_[a];
    axis.anchorMm += report.dMm[a];
    axis.speedMmPerS = report.dMm[a] / intervalS_;
    axis.correctionMm = beforeMm[a] - axis.anchorMm;
  }
  mode_ = nextMode_;
  if (mode_ == TrajectoryMode::Hold) axes_[0].correctionMm = axes_[1].correctionMm = 0.0;
  anchorTimeS_ = takeS;
  hasAnchor_ = true;
  ++reportsTaken_;
}

void TrajectoryReconstructor::render(double startTimeS, double sampleDurS, int numSamples, double originMm, float* xMm,
                                     float* yMm, float* vxMmPerS, float* vyMmPerS) {
  render(startTimeS, sampleDurS, numSamples, originMm, 0.0, xMm, yMm, vxMmPerS, vyMmPerS);
}

void TrajectoryReconstructor::render(double startTimeS, double sampleDurS, int numSamples, double originXMm,
                                     double originYMm, float* xMm, float* yMm, float* vxMmPerS, float* vyMmPerS) {
  if (numSamples <= 0) return;
  const SampleClock clock{startTimeS, sampleDurS};
  // Sample times that do not increase (a bad sample duration) cannot be searched: then every
  // sample is a run of its own, which is the per-sample rule itself.
  const bool searchable = std::isfinite(sampleDurS) && sampleDurS >= 0.0;
  const Outputs out{{xMm, yMm}, {vxMmPerS, vyMmPerS}, {originXMm, originYMm}};
  int i = 0;
  while (i < numSamples) {
    takeDueReports(clock, i);
    // At most kMaxRun samples at a time: renderRun keeps their phases on the stack.
    const int end = searchable ? std::min(i + kMaxRun, endOfRun(clock, i, numSamples)) : i + 1;
    renderRun(clock, i, end, out);
    lastRenderTimeS_ = clock.timeS(end - 1);
    hasRendered_ = true;
    i = end;
  }
}

// Every pending report whose time has come by sample i, in order. take() needs the time of the
// sample before (lastRenderTimeS_), which render() keeps up to date at each run's end.
void TrajectoryReconstructor::takeDueReports(const SampleClock& clock, int i) {
  const double nowS = clock.timeS(i);
  while (pendingCount_ > 0 && queue_[pendingHead_].timeS <= nowS) {
    take(queue_[pendingHead_], nowS);
    pendingHead_ = (pendingHead_ + 1) % kQueueCapacity;
    --pendingCount_;
  }
}

// The first sample after i at which the next pending report is due (numSamples if none is):
// sample times increase, so a binary search finds it with the per-sample comparison.
int TrajectoryReconstructor::endOfRun(const SampleClock& clock, int i, int numSamples) const {
  if (pendingCount_ == 0) return numSamples;
  const double dueS = queue_[pendingHead_].timeS;
  return firstSampleWhere(i + 1, numSamples, [&](int k) { return dueS <= clock.timeS(k); });
}

// Samples [from, to) with no report taken between them. The phase s rises with the sample, so
// each of positionAt's and speedAt's branches holds for one contiguous stretch: the stretches'
// ends are found once (with the very comparisons those functions make, so the output is
// bit-for-bit theirs), and each is filled by a loop without branches.
void TrajectoryReconstructor::renderRun(const SampleClock& clock, int from, int to, const Outputs& out) {
  const Phase phase{clock, anchorTimeS_, intervalS_};
  const auto firstAtOrAbove = [&](int lo, double threshold) {
    return firstSampleWhere(lo, to, [&](int k) { return !(phase.at(k) < threshold); });
  };
  // Samples up to the anchor's time (s <= 0: a report taken at a sample's own time) neither
  // extrapolate nor have faded: positionAt's std::max(0, s) is 0 there and s itself after, so
  // the loops need no max. A NaN phase counts as past every end: positionAt reads the anchor.
  const int afterAnchor = firstSampleWhere(from, to, [&](int k) { return !(phase.at(k) <= 0.0); });
  // Stretch ends, in T: 1 ends the fade, kExtrapolateT the extrapolation, kStaleT the held speed,
  // kStaleT + kFadeT the fade of speed and extrapolation.
  const int fadeEnd = firstAtOrAbove(afterAnchor, 1.0);
  const int extrapolateEnd = firstAtOrAbove(fadeEnd, kExtrapolateT);
  const int staleStart = firstAtOrAbove(extrapolateEnd, kStaleT);
  const int restStart = firstAtOrAbove(staleStart, kStaleT + kFadeT);
  // s of the samples whose output depends on it, computed once for both axes in a loop of its
  // own (the division is most of a sample's cost): up to the end of the fade (linear) or of the
  // extrapolation (predictive), and over the fade of speed. s(k) = phases[k - from].
  double phases[kMaxRun];
  const int variableEnd = !hasAnchor_ || mode_ == TrajectoryMode::Hold ? from
                          : mode_ == TrajectoryMode::Linear            ? fadeEnd
                                                                       : extrapolateEnd;
  phase.fill(phases, from, afterAnchor, variableEnd);
  if (hasAnchor_) phase.fill(phases, from, staleStart, restStart);
  const auto s = [&](int k) { return phases[k - from]; };
  const double lastPhase = phase.at(to - 1);
  for (int a = 0; a < 2; ++a) {
    const Axis& axis = axes_[a];
    renderedMm_[a] = hasAnchor_ ? positionAt(axis, lastPhase) : axis.anchorMm;
    renderedSpeedMmPerS_[a] = hasAnchor_ ? speedAt(axis, lastPhase) : 0.0;
    if (float* p = out.positionMm[a]) {
      const double originMm = out.originMm[a];
      const auto put = [&](int lo, int hi, auto positionOf) {
        for (int k = lo; k < hi; ++k) p[k] = static_cast<float>(positionOf(k) - originMm);
      };
      const auto anchor = [&](int) { return axis.anchorMm; };
      if (!hasAnchor_ || mode_ == TrajectoryMode::Hold) {
        put(from, to, anchor);
      } else if (mode_ == TrajectoryMode::Linear) {
        put(from, afterAnchor, [&](int) { return blend(axis, 0.0, 1.0 - 0.0); });
        put(afterAnchor, fadeEnd, [&](int k) { return blend(axis, 0.0, 1.0 - s(k)); });
        put(fadeEnd, to, anchor);
      } else {
        // Extrapolation and fade are never both 0 before restStart (the fade is > 0 below s = 1,
        // the extrapolation >= 1 from there to kStaleT and > 0 below kStaleT + kFadeT), so
        // positionAt's exact-anchor shortcut applies from restStart on only.
        put(from, afterAnchor, [&](int) { return blend(axis, 0.0, 1.0 - 0.0); });
        put(afterAnchor, fadeEnd, [&](int k) { return blend(axis, s(k), 1.0 - s(k)); });
        put(fadeEnd, extrapolateEnd, [&](int k) { return blend(axis, s(k), 0.0); });
        put(extrapolateEnd, staleStart, [&](int) { return blend(axis, kExtrapolateT, 0.0); });
        put(staleStart, restStart,
            [&](int k) { return blend(axis, kExtrapolateT * (1.0 - (s(k) - kStaleT) / kFadeT), 0.0); });
        put(restStart, to, anchor);
      }
    }
    if (float* v = out.speedMmPerS[a]) {
      const double speed = hasAnchor_ ? axis.speedMmPerS : 0.0;
      const int held = hasAnchor_ ? staleStart : from, fading = hasAnchor_ ? restStart : from;
      std::fill(v + from, v + held, static_cast<float>(speed));
      for (int k = held; k < fading; ++k) v[k] = static_cast<float>(speed * (1.0 - (s(k) - kStaleT) / kFadeT));
      std::fill(v + fading, v + to, 0.0f);
    }
  }
}

}  // namespace kf
