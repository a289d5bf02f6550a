#include "sim/SimDevice.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

SimDevice::SimDevice(const DeviceSpec& spec, const SimParams& params, const HandScript& hand)
    : spec_(spec),
      params_(params),
      hand_(hand),
      puck_(params.puckMassKg),
      magnet_(spec.magnetLagS, params.stepS, spec.minForceN),
      sensor_(spec, params, 0.0),
      buffer_(kReportBufferCapacity) {}

double SimDevice::handPushN(double timeS) const {
  if (hand_.isIdle()) return 0.0;
  if (hand_.isForce()) return hand_.constantForceN();
  // A spring-damper between hand and puck, limited to what a fingertip pushes.
  const HandTarget target = hand_.at(timeS);
  const double errorM = (target.positionMm - positionMm()) * 1e-3;
  const double speedErrorMPerS = (target.speedMmPerS - speedMmPerS()) * 1e-3;
  const double pushN = params_.handStiffnessNPerM * errorM + params_.handDampingNSPerM * speedErrorMPerS;
  return std::clamp(pushN, -params_.handMaxForceN, params_.handMaxForceN);
}

void SimDevice::step() {
  const double startS = timeS();
  const double startMm = positionMm();
  handForceN_ = handPushN(startS);
  puck_.step(params_.stepS, handForceN_, magnet_.forceN());
  magnet_.step();
  ++stepIndex_;
  const double endS = timeS();
  const double endMm = positionMm();
  while (sensor_.nextReportTimeS() <= endS) {
    // Position at the report instant, linear within the step.
    const double fraction = (sensor_.nextReportTimeS() - startS) / params_.stepS;
    const double atMm = startMm + (endMm - startMm) * std::clamp(fraction, 0.0, 1.0);
    MouseReport report;
    if (sensor_.takeReport(atMm, report)) storeReport(report);
  }
}

void SimDevice::advanceTo(double timeS) {
  // The small epsilon keeps times that are whole steps from losing one to rounding.
  const auto targetStep = static_cast<int64_t>(std::floor(timeS / params_.stepS + 1e-6));
  while (stepIndex_ < targetStep) step();
}

void SimDevice::storeReport(const MouseReport& report) {
  if (bufferCount_ == kReportBufferCapacity) {
    // Nobody polls: keep the newest.
    bufferHead_ = (bufferHead_ + 1) % kReportBufferCapacity;
    --bufferCount_;
    ++bufferOverflows_;
  }
  buffer_[(bufferHead_ + bufferCount_) % kReportBufferCapacity] = report;
  ++bufferCount_;
}

int SimDevice::pollReports(double untilTimeS, MouseReport* out, int capacity) {
  advanceTo(untilTimeS);
  int written = 0;
  while (written < capacity && bufferCount_ > 0) {
    out[written++] = buffer_[bufferHead_];
    bufferHead_ = (bufferHead_ + 1) % kReportBufferCapacity;
    --bufferCount_;
  }
  return written;
}

void SimDevice::commandForce(double timeS, float forceN) {
  advanceTo(timeS);
  magnet_.command(forceN);
}

void SimDevice::driveOff() { magnet_.command(spec_.minForceN); }

}  // namespace kf
