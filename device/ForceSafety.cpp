#include "ForceSafety.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

ForceSafety::ForceSafety(const DeviceSpec& spec) : spec_(spec), commandedForceN_(static_cast<float>(spec.minForceN)) {}

float ForceSafety::applyFrame(const ForceFrame& frame, double arrivalS) {
  const double minN = spec_.minForceN;
  const double maxN = spec_.maxForceN;
  double targetN = frame.forceN;
  if (!std::isfinite(targetN)) targetN = minN;
  targetN = std::clamp(targetN, minN, maxN);

  double elapsedS = spec_.forceFramePeriodS;
  if (haveFrame_ && std::isfinite(frame.timeS))
    elapsedS = std::max(frame.timeS - lastFrameTimeS_, spec_.forceFramePeriodS);
  const double maxStepN = spec_.maxForceSlewNPerS * elapsedS;
  const double previousN = commandedForceN_;
  targetN = std::clamp(targetN, previousN - maxStepN, previousN + maxStepN);
  // The float rounding of a clamped value must not leave the range.
  commandedForceN_ = std::clamp(static_cast<float>(targetN), static_cast<float>(minN), static_cast<float>(maxN));

  if (std::isfinite(frame.timeS)) lastFrameTimeS_ = frame.timeS;
  lastArrivalS_ = arrivalS;
  haveFrame_ = true;
  watchdogArmed_ = true;
  return commandedForceN_;
}

bool ForceSafety::checkWatchdog(double nowS) {
  if (!watchdogArmed_ || nowS - lastArrivalS_ < spec_.watchdogS) return false;
  resetToOff();
  return true;
}

void ForceSafety::resetToOff() {
  commandedForceN_ = static_cast<float>(spec_.minForceN);
  haveFrame_ = false;
  watchdogArmed_ = false;
}

}  // namespace kf
