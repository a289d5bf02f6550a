#include "core/force/ForceSafety.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

ForceSafety::ForceSafety(const DeviceSpec& spec)
    : spec_(spec),
      calibration_(CalibrationTable::linear(spec.minForceN, spec.maxForceN)),
      commandedForceN_(static_cast<float>(spec.minForceN)),
      slewedN_(spec.minForceN) {}

double ForceSafety::heatDriveLimit() const {
  // Full drive below 90% of the rated heat, sqrt(rated) (what the coil takes for ever) at it,
  // linear in between: continuous, so a hot coil is derated smoothly, without chatter.
  const double rated = spec_.heatRatedDuty;
  const double over = std::clamp((heat_ - 0.9 * rated) / (0.1 * rated), 0.0, 1.0);
  return 1.0 - (1.0 - std::sqrt(rated)) * over;
}

float ForceSafety::applyFrame(const ForceFrame& frame, double arrivalS) {
  const double minN = spec_.minForceN;
  const double maxN = spec_.maxForceN;
  // 1, 2: non-finite -> minimum, clamp.
  double targetN = frame.forceN;
  if (!std::isfinite(targetN)) targetN = minN;
  targetN = std::clamp(targetN, minN, maxN);
  // The float forms of the limits are the limits (0.14f is a little more than 0.14): so the
  // minimum is drive 0 exactly, the maximum full drive.
  if (targetN <= static_cast<float>(minN)) targetN = minN;
  if (targetN >= static_cast<float>(maxN)) targetN = maxN;

  // 3: slew.
  double elapsedS = spec_.forceFramePeriodS;
  if (haveFrame_ && std::isfinite(frame.timeS))
    elapsedS = std::max(frame.timeS - lastFrameTimeS_, spec_.forceFramePeriodS);
  const double maxStepN = spec_.maxForceSlewNPerS * elapsedS;
  targetN = std::clamp(targetN, slewedN_ - maxStepN, slewedN_ + maxStepN);
  slewedN_ = targetN;

  // Heat: the previous drive was held over the time since the previous frame.
  const double blend = 1.0 - std::exp(-elapsedS / spec_.heatTimeConstantS);
  heat_ += (static_cast<double>(driveLevel_) * driveLevel_ - heat_) * blend;

  // 4, 5, 6: calibration, hard drive limit, heat derating.
  const double drive = calibration_.driveForForce(targetN);
  const double limit = std::min(spec_.maxDriveLevel, heatDriveLimit());
  double commandedN = targetN;
  double limitedDrive = drive;
  if (drive > limit) {
    limitedDrive = limit;
    commandedN = calibration_.forceForDrive(limit);
    ++driveLimitedFrames_;
  } else if (targetN > calibration_.maxForceN()) {
    commandedN = calibration_.maxForceN();  // the board gives no more than its table's top
  } else if (targetN < calibration_.minForceN()) {
    commandedN = calibration_.minForceN();  // nor less than its bottom
  }
  driveLevel_ = static_cast<float>(std::clamp(limitedDrive, 0.0, 1.0));
  // The float rounding of a clamped value must not leave the range.
  commandedForceN_ = std::clamp(static_cast<float>(commandedN), static_cast<float>(minN), static_cast<float>(maxN));

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

void ForceSafety::continueFrom(const ForceSafety& previous, double driveScale) {
  heat_ = previous.heat_ * driveScale * driveScale;
  driveLevel_ = static_cast<float>(std::clamp(previous.driveLevel_ * driveScale, 0.0, 1.0));
  slewedN_ = previous.slewedN_;
  commandedForceN_ = previous.commandedForceN_;
  lastFrameTimeS_ = previous.lastFrameTimeS_;
  lastArrivalS_ = previous.lastArrivalS_;
  haveFrame_ = previous.haveFrame_;
  watchdogArmed_ = previous.watchdogArmed_;
}

void ForceSafety::resetToOff() {
  commandedForceN_ = static_cast<float>(spec_.minForceN);
  slewedN_ = spec_.minForceN;
  driveLevel_ = 0.0f;
  haveFrame_ = false;
  watchdogArmed_ = false;
}

}  // namespace kf
