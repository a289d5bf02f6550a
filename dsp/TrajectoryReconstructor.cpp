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
  enqueue(reportTimeS, dxMm, dyMm, false);
}

void TrajectoryReconstructor::addShift(double timeS, double dxMm, double dyMm) { enqueue(timeS, dxMm, dyMm, true); }

void TrajectoryReconstructor::enqueue(double timeS, double dxMm, double dyMm, bool isShift) {
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
  queue_[(pendingHead_ + pendingCount_) % kQueueCapacity] = Pending{timeS, {dxMm, dyMm}, isShift};
  ++pendingCount_;
  lastQueuedTimeS_ = timeS;
}

double TrajectoryReconstructor::positionAt(const Axis& axis, double sinceAnchorS) const {
  const double s = sinceAnchorS / intervalS_;  // in intervals
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
  return axis.anchorMm + axis.speedMmPerS * (extrapolateT * intervalS_) + axis.correctionMm * fade;
}

double TrajectoryReconstructor::speedAt(const Axis& axis, double sinceAnchorS) const {
  const double s = sinceAnchorS / intervalS_;
  if (s < kStaleT) return axis.speedMmPerS;
  if (s < kStaleT + kFadeT) return axis.speedMmPerS * (1.0 - (s - kStaleT) / kFadeT);
  return 0.0;
}

void TrajectoryReconstructor::take(const Pending& report, double nowS) {
  if (report.isShift) {
    // Anchor and everything relative to it move together: the output steps by the shift.
    for (int a = 0; a < 2; ++a) axes_[a].anchorMm += report.dMm[a];
    return;
  }
  // Taken at its own time, or at the last rendered sample if that is already past it, so the
  // position just before it is what was (or would have been) output.
  double takeS = std::min(report.timeS, nowS);
  if (hasRendered_) takeS = std::max(takeS, lastRenderTimeS_);
  double beforeMm[2];
  for (int a = 0; a < 2; ++a) beforeMm[a] = hasAnchor_ ? positionAt(axes_[a], takeS - anchorTimeS_) : axes_[a].anchorMm;
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
  float* positionOut[2] = {xMm, yMm};
  float* speedOut[2] = {vxMmPerS, vyMmPerS};
  const double originMm[2] = {originXMm, originYMm};
  for (int i = 0; i < numSamples; ++i) {
    const double nowS = startTimeS + i * sampleDurS;
    while (pendingCount_ > 0 && queue_[pendingHead_].timeS <= nowS) {
      take(queue_[pendingHead_], nowS);
      pendingHead_ = (pendingHead_ + 1) % kQueueCapacity;
      --pendingCount_;
    }
    const double sinceS = nowS - anchorTimeS_;
    for (int a = 0; a < 2; ++a) {
      const Axis& axis = axes_[a];
      const double pMm = hasAnchor_ ? positionAt(axis, sinceS) : axis.anchorMm;
      const double vMmPerS = hasAnchor_ ? speedAt(axis, sinceS) : 0.0;
      renderedMm_[a] = pMm;
      renderedSpeedMmPerS_[a] = vMmPerS;
      if (positionOut[a]) positionOut[a][i] = static_cast<float>(pMm - originMm[a]);
      if (speedOut[a]) speedOut[a][i] = static_cast<float>(vMmPerS);
    }
    lastRenderTimeS_ = nowS;
    hasRendered_ = true;
  }
}

}  // namespace kf
